#pragma once
// The OpenSim Function objects that appear in .osim models: the functions of
// a CustomJoint's TransformAxis (joint kinematics as functions of a
// coordinate) and the x/y/z_location functions of a MovingPathPoint. Each
// one is a scalar function of one scalar argument y = f(x), evaluated the way
// OpenSim 4 evaluates it (same extrapolation outside the data range, same
// spline end conditions), so kinematics computed from a model read here match
// OpenSim's.
//
// Function is a small value type (a std::variant over the concrete kinds);
// copies are cheap (a MultiplierFunction shares its immutable inner function).

#include <cstddef>
#include <memory>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace mmm::opensim {

// OpenSim <Constant>: y = value.
struct Constant {
  double value = 0.0;
};

// OpenSim <LinearFunction>: y = slope * x + intercept. The XML property
// <coefficients> holds "slope intercept" in that order.
struct LinearFunction {
  double slope = 1.0;
  double intercept = 0.0;
};

// OpenSim <PolynomialFunction>: <coefficients> c0 c1 ... c(n-1) from the
// highest to the lowest order, y = c0 x^(n-1) + c1 x^(n-2) + ... + c(n-1).
// No coefficients means y = 0.
struct PolynomialFunction {
  std::vector<double> coefficients;
};

// OpenSim <SimmSpline>: the interpolating cubic spline of SIMM, i.e. the
// routine SPLINE of Forsythe, Malcolm & Moler, "Computer Methods for
// Mathematical Computations" (1977): C2 cubic pieces through every (x, y)
// point, with end conditions that give the end intervals the third
// derivative of the cubic through the first (last) 4 points. It is therefore
// NOT the "natural" spline: it reproduces any cubic exactly from >= 4 points,
// any quadratic from 3 points and a straight line from 2 points.
// Outside [x.front(), x.back()] it continues along the tangent at the end
// point (linear extrapolation), as OpenSim does.
class SimmSpline {
 public:
  // x  #n abscissae, strictly increasing, finite (n >= 2)
  // y  #n ordinates, finite
  // Throws InvalidInputError when the counts differ, n < 2, a value is not
  // finite or x does not strictly increase (the message names the index).
  SimmSpline(std::vector<double> x, std::vector<double> y);

  [[nodiscard]] double evaluate(double x) const;
  // dy/dx; the end-point slope outside the data range.
  [[nodiscard]] double derivative(double x) const;

  [[nodiscard]] const std::vector<double>& x() const { return x_; }
  [[nodiscard]] const std::vector<double>& y() const { return y_; }

 private:
  // Index k of the interval [x_k, x_k+1] holding x (x inside the range).
  [[nodiscard]] std::size_t interval(double x) const;

  std::vector<double> x_;
  std::vector<double> y_;
  // On interval k, y = y_k + b_k t + c_k t^2 + d_k t^3 with t = x - x_k.
  std::vector<double> b_;
  std::vector<double> c_;
  std::vector<double> d_;
};

// OpenSim <PiecewiseLinearFunction>: straight segments between the (x, y)
// points; outside the data range the first (last) segment is extended.
class PiecewiseLinearFunction {
 public:
  // Same contract and errors as SimmSpline.
  PiecewiseLinearFunction(std::vector<double> x, std::vector<double> y);

  [[nodiscard]] double evaluate(double x) const;
  // Slope of the segment holding x (of the right-hand segment at a knot).
  [[nodiscard]] double derivative(double x) const;

  [[nodiscard]] const std::vector<double>& x() const { return x_; }
  [[nodiscard]] const std::vector<double>& y() const { return y_; }

 private:
  [[nodiscard]] std::size_t segment(double x) const;

  std::vector<double> x_;
  std::vector<double> y_;
  std::vector<double> slopes_;  // slopes_[k] of segment k; last one repeated
};

class Function;

// OpenSim <MultiplierFunction>: y = scale * f(x). OpenSim's scale tool wraps
// the translation functions of scaled models (e.g. knee translations) in it.
class MultiplierFunction {
 public:
  MultiplierFunction(Function function, double scale);

  [[nodiscard]] const Function& function() const { return *function_; }
  [[nodiscard]] double scale() const { return scale_; }

 private:
  std::shared_ptr<const Function> function_;  // never null; immutable, so sharing is a copy
  double scale_ = 1.0;
};

// Any of the function kinds above. A default-constructed Function is
// Constant{0}.
class Function {
 public:
  using Variant = std::variant<Constant, LinearFunction, PolynomialFunction, SimmSpline,
                               PiecewiseLinearFunction, MultiplierFunction>;

  Function() = default;
  // Implicit on purpose: a Function is "one of" these kinds.
  Function(Constant f) : value_(f) {}
  Function(LinearFunction f) : value_(f) {}
  Function(PolynomialFunction f) : value_(std::move(f)) {}
  Function(SimmSpline f) : value_(std::move(f)) {}
  Function(PiecewiseLinearFunction f) : value_(std::move(f)) {}
  Function(MultiplierFunction f) : value_(std::move(f)) {}

  [[nodiscard]] double evaluate(double x) const;
  [[nodiscard]] double derivative(double x) const;

  // The OpenSim element name of the kind: "Constant", "LinearFunction",
  // "PolynomialFunction", "SimmSpline", "PiecewiseLinearFunction",
  // "MultiplierFunction".
  [[nodiscard]] std::string_view type_name() const;

  [[nodiscard]] const Variant& variant() const { return value_; }
  // The concrete function when it is a T, else nullptr.
  template <typename T>
  [[nodiscard]] const T* get_if() const {
    return std::get_if<T>(&value_);
  }

 private:
  Variant value_ = Constant{};
};

}  // namespace mmm::opensim

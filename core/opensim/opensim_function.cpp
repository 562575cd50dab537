// SimmSpline coefficients: the FMM spline (Forsythe, Malcolm & Moler 1977,
// routine SPLINE), which SIMM and OpenSim use.
//
//   h_i = x_i+1 - x_i,  D_i = (y_i+1 - y_i) / h_i,  s_i = S''(x_i) / 6
//   interior rows:  h_i-1 s_i-1 + 2 (h_i-1 + h_i) s_i + h_i s_i+1 = D_i - D_i-1
//   end rows:       -h_0 s_0 + h_0 s_1          =  h_0^2  f[x0, x1, x2, x3]
//                   h_m s_m - h_m s_m+1         = -h_m^2  f[x_n-4, ..., x_n-1]  (m = n-2)
//   (f[...] third divided differences; 0 when n = 3, so that the end pieces
//   have zero third derivative: a quadratic is reproduced). The tridiagonal
//   system is solved by elimination without pivoting in the same order as the
//   original routine, then per interval
//   b_i = D_i - h_i (s_i+1 + 2 s_i),  c_i = 3 s_i,  d_i = (s_i+1 - s_i) / h_i.

#include "core/opensim/opensim_function.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"

namespace mmm::opensim {

namespace {

// Common checks of the (x, y) tables of SimmSpline and PiecewiseLinearFunction.
void check_points(const std::vector<double>& x, const std::vector<double>& y,
                  std::string_view kind) {
  const std::string name(kind);
  if (x.size() != y.size()) {
    throw InvalidInputError(name + " has " + std::to_string(x.size()) + " x values but " +
                            std::to_string(y.size()) +
                            " y values; expected one y per x (check <x> and <y>)");
  }
  if (x.size() < 2) {
    throw InvalidInputError(name + " has " + std::to_string(x.size()) +
                            " points; at least 2 are needed (use a Constant for a fixed value)");
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
      throw InvalidInputError(name + " point " + std::to_string(i) + " is not finite (NaN or inf)");
    }
    if (i > 0 && !(x[i] > x[i - 1])) {
      throw InvalidInputError(name + " x values must strictly increase, but x[" +
                              std::to_string(i) + "] = " + std::to_string(x[i]) + " follows x[" +
                              std::to_string(i - 1) + "] = " + std::to_string(x[i - 1]) +
                              "; sort the points and remove duplicates");
    }
  }
}

// Index k with x_k <= x < x_k+1 for x strictly inside (x.front(), x.back()),
// and the last interval for x == x.back().
std::size_t find_interval(const std::vector<double>& xs, double x) {
  const auto above = std::upper_bound(xs.begin(), xs.end(), x);
  const auto k = static_cast<std::size_t>(std::max<std::ptrdiff_t>(above - xs.begin() - 1, 0));
  return std::min(k, xs.size() - 2);
}

// Third divided difference f[x_i, ..., x_i+3] from the first differences
// jump_i = D_i - D_i-1 (the right-hand sides of the interior rows).
double third_divided_difference(const std::vector<double>& x, const std::vector<double>& jump,
                                std::size_t i) {
  const double second_left = jump[i + 1] / (x[i + 2] - x[i]);
  const double second_right = jump[i + 2] / (x[i + 3] - x[i + 1]);
  return (second_right - second_left) / (x[i + 3] - x[i]);
}

}  // namespace

// ---------------------------------------------------------------- SimmSpline

SimmSpline::SimmSpline(std::vector<double> x, std::vector<double> y)
    : x_(std::move(x)), y_(std::move(y)) {
  check_points(x_, y_, "SimmSpline");
  const std::size_t n = x_.size();
  b_.assign(n, 0.0);
  c_.assign(n, 0.0);
  d_.assign(n, 0.0);
  if (n == 2) {
    const double slope = (y_[1] - y_[0]) / (x_[1] - x_[0]);
    b_[0] = b_[1] = slope;
    return;
  }
  const std::size_t last = n - 1;
  std::vector<double> h(n - 1);
  std::vector<double> slope(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    h[i] = x_[i + 1] - x_[i];
    slope[i] = (y_[i + 1] - y_[i]) / h[i];
  }
  // Tridiagonal system: diagonal `diag`, off-diagonal h (symmetric), right-hand side `rhs`.
  std::vector<double> diag(n);
  std::vector<double> rhs(n, 0.0);
  for (std::size_t i = 1; i < last; ++i) {
    diag[i] = 2.0 * (h[i - 1] + h[i]);
    rhs[i] = slope[i] - slope[i - 1];
  }
  diag[0] = -h[0];
  diag[last] = -h[last - 1];
  if (n > 3) {
    rhs[0] = h[0] * h[0] * third_divided_difference(x_, rhs, 0);
    rhs[last] = -h[last - 1] * h[last - 1] * third_divided_difference(x_, rhs, n - 4);
  }
  for (std::size_t i = 1; i < n; ++i) {
    const double factor = h[i - 1] / diag[i - 1];
    diag[i] -= factor * h[i - 1];
    rhs[i] -= factor * rhs[i - 1];
  }
  std::vector<double> sigma(n);
  sigma[last] = rhs[last] / diag[last];
  for (std::size_t j = 0; j < last; ++j) {
    const std::size_t i = last - 1 - j;
    sigma[i] = (rhs[i] - h[i] * sigma[i + 1]) / diag[i];
  }
  for (std::size_t i = 0; i < last; ++i) {
    b_[i] = slope[i] - h[i] * (sigma[i + 1] + 2.0 * sigma[i]);
    c_[i] = 3.0 * sigma[i];
    d_[i] = (sigma[i + 1] - sigma[i]) / h[i];
  }
  b_[last] = slope[last - 1] + h[last - 1] * (sigma[last - 1] + 2.0 * sigma[last]);
  c_[last] = 3.0 * sigma[last];
  d_[last] = d_[last - 1];
}

std::size_t SimmSpline::interval(double x) const { return find_interval(x_, x); }

double SimmSpline::evaluate(double x) const {
  if (x < x_.front()) return y_.front() + (x - x_.front()) * b_.front();
  if (x > x_.back()) return y_.back() + (x - x_.back()) * b_.back();
  if (x == x_.back()) return y_.back();
  const std::size_t k = interval(x);
  const double t = x - x_[k];
  return y_[k] + t * (b_[k] + t * (c_[k] + t * d_[k]));
}

double SimmSpline::derivative(double x) const {
  if (x < x_.front()) return b_.front();
  if (x >= x_.back()) return b_.back();
  const std::size_t k = interval(x);
  const double t = x - x_[k];
  return b_[k] + t * (2.0 * c_[k] + 3.0 * t * d_[k]);
}

// --------------------------------------------------- PiecewiseLinearFunction

PiecewiseLinearFunction::PiecewiseLinearFunction(std::vector<double> x, std::vector<double> y)
    : x_(std::move(x)), y_(std::move(y)) {
  check_points(x_, y_, "PiecewiseLinearFunction");
  slopes_.resize(x_.size());
  for (std::size_t i = 0; i + 1 < x_.size(); ++i) {
    slopes_[i] = (y_[i + 1] - y_[i]) / (x_[i + 1] - x_[i]);
  }
  slopes_.back() = slopes_[x_.size() - 2];
}

std::size_t PiecewiseLinearFunction::segment(double x) const { return find_interval(x_, x); }

double PiecewiseLinearFunction::evaluate(double x) const {
  if (x < x_.front()) return y_.front() + (x - x_.front()) * slopes_.front();
  if (x > x_.back()) return y_.back() + (x - x_.back()) * slopes_.back();
  if (x == x_.back()) return y_.back();
  const std::size_t k = segment(x);
  return y_[k] + (x - x_[k]) * slopes_[k];
}

double PiecewiseLinearFunction::derivative(double x) const {
  if (x < x_.front()) return slopes_.front();
  if (x >= x_.back()) return slopes_.back();
  return slopes_[segment(x)];
}

// -------------------------------------------------------- MultiplierFunction

MultiplierFunction::MultiplierFunction(Function function, double scale)
    : function_(std::make_shared<const Function>(std::move(function))), scale_(scale) {}

// ------------------------------------------------------------------ Function

namespace {

struct Evaluator {
  double x;
  double operator()(const Constant& f) const { return f.value; }
  double operator()(const LinearFunction& f) const { return f.slope * x + f.intercept; }
  double operator()(const PolynomialFunction& f) const {
    double value = 0.0;
    for (const double coefficient : f.coefficients) value = value * x + coefficient;
    return value;
  }
  double operator()(const SimmSpline& f) const { return f.evaluate(x); }
  double operator()(const PiecewiseLinearFunction& f) const { return f.evaluate(x); }
  double operator()(const MultiplierFunction& f) const {
    return f.scale() * f.function().evaluate(x);
  }
};

struct Differentiator {
  double x;
  double operator()(const Constant& /*f*/) const { return 0.0; }
  double operator()(const LinearFunction& f) const { return f.slope; }
  double operator()(const PolynomialFunction& f) const {
    // Horner on the derivative: coefficient c_i multiplies x^(n-1-i).
    const std::size_t n = f.coefficients.size();
    double value = 0.0;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      value = value * x + static_cast<double>(n - 1 - i) * f.coefficients[i];
    }
    return value;
  }
  double operator()(const SimmSpline& f) const { return f.derivative(x); }
  double operator()(const PiecewiseLinearFunction& f) const { return f.derivative(x); }
  double operator()(const MultiplierFunction& f) const {
    return f.scale() * f.function().derivative(x);
  }
};

struct TypeName {
  std::string_view operator()(const Constant& /*f*/) const { return "Constant"; }
  std::string_view operator()(const LinearFunction& /*f*/) const { return "LinearFunction"; }
  std::string_view operator()(const PolynomialFunction& /*f*/) const {
    return "PolynomialFunction";
  }
  std::string_view operator()(const SimmSpline& /*f*/) const { return "SimmSpline"; }
  std::string_view operator()(const PiecewiseLinearFunction& /*f*/) const {
    return "PiecewiseLinearFunction";
  }
  std::string_view operator()(const MultiplierFunction& /*f*/) const {
    return "MultiplierFunction";
  }
};

}  // namespace

double Function::evaluate(double x) const { return std::visit(Evaluator{x}, value_); }

double Function::derivative(double x) const { return std::visit(Differentiator{x}, value_); }

std::string_view Function::type_name() const { return std::visit(TypeName{}, value_); }

}  // namespace mmm::opensim

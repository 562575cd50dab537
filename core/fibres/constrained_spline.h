#pragma once
// Constrained cubic spline (Kruger, "Constrained cubic spline interpolation
// for chemical engineering applications", 2002): a piecewise cubic through
// the points (x_i, y_i) whose slope at each point comes from its neighbours'
// secants instead of from a C2 condition, so that it does not overshoot:
//
//   s_i  = (y_i+1 - y_i) / (x_i+1 - x_i)                       secant slopes
//   f'_i = 2 s_i-1 s_i / (s_i-1 + s_i)   if s_i-1 s_i > 0      (harmonic mean)
//        = 0                             otherwise (the data turn, or are flat)
//   f'_0 = 3/2 s_0   - f'_1 / 2                                 end slopes
//   f'_n = 3/2 s_n-1 - f'_n-1 / 2
//   (two points: f'_0 = f'_1 = s_0, the solution of both end rules, a line)
//   on [x_i, x_i+1]: the cubic Hermite piece with values y_i, y_i+1 and slopes
//   f'_i, f'_i+1 (Kruger's a, b, c, d are this cubic in monomial form).
//
// The curve is C1, not C2 (the second derivative jumps at the points). It
// passes through every point and reproduces a straight line. Every piece is
// monotone and stays between its two end values: each slope is 0 or has the
// sign of the secants beside it, the harmonic mean lies below twice the
// smaller secant and the end slopes between 1/2 and 3/2 of theirs, so slope /
// secant stays in [0, 2] at both ends of every piece, inside the Fritsch &
// Carlson (1980) monotonicity region ([0, 3] suffices). Where an interpolating
// C2 spline (opensim::SimmSpline) swings past a step in the data, this one
// does not; the price is flattening at the turns of the data.

#include <cstddef>
#include <vector>

namespace mmm::fibres {

class ConstrainedSpline {
 public:
  // x  #n abscissae, strictly increasing, finite (n >= 2)
  // y  #n ordinates, finite
  // Throws InvalidInputError when the counts differ, n < 2, a value is not
  // finite or x does not strictly increase (the message names the index).
  ConstrainedSpline(std::vector<double> x, std::vector<double> y);

  // y at x. Outside [x.front(), x.back()] the curve continues along the
  // tangent at the end point (linear extrapolation, as SimmSpline does).
  [[nodiscard]] double evaluate(double x) const;
  // dy/dx at x; the end-point slope outside the data range.
  [[nodiscard]] double derivative(double x) const;

  [[nodiscard]] const std::vector<double>& x() const { return x_; }
  [[nodiscard]] const std::vector<double>& y() const { return y_; }
  // f'_i, the slope at each point (see above).
  [[nodiscard]] const std::vector<double>& slopes() const { return slopes_; }

 private:
  // Index k of the interval [x_k, x_k+1] holding x (x inside the range).
  [[nodiscard]] std::size_t interval(double x) const;

  std::vector<double> x_;
  std::vector<double> y_;
  std::vector<double> slopes_;
};

}  // namespace mmm::fibres

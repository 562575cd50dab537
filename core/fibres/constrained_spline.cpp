#include "core/fibres/constrained_spline.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

void check_spline_points(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size()) {
    throw InvalidInputError("constrained spline: " + std::to_string(x.size()) + " x values but " +
                            std::to_string(y.size()) + " y values; expected one y per x");
  }
  if (x.size() < 2) {
    throw InvalidInputError("constrained spline: " + std::to_string(x.size()) +
                            " points; at least 2 are needed");
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
      throw InvalidInputError("constrained spline: point " + std::to_string(i) +
                              " is not finite (NaN or inf)");
    }
    if (i > 0 && !(x[i] > x[i - 1])) {
      throw InvalidInputError("constrained spline: x values must strictly increase, but x[" +
                              std::to_string(i) + "] = " + std::to_string(x[i]) + " follows x[" +
                              std::to_string(i - 1) + "] = " + std::to_string(x[i - 1]) +
                              "; hint: sort the points and remove duplicates");
    }
  }
}

}  // namespace

ConstrainedSpline::ConstrainedSpline(std::vector<double> x, std::vector<double> y)
    : x_(std::move(x)), y_(std::move(y)) {
  check_spline_points(x_, y_);
  const std::size_t n = x_.size();
  std::vector<double> secant(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) secant[i] = (y_[i + 1] - y_[i]) / (x_[i + 1] - x_[i]);
  slopes_.assign(n, 0.0);
  if (n == 2) {
    slopes_[0] = slopes_[1] = secant[0];
    return;
  }
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double left = secant[i - 1];
    const double right = secant[i];
    if (left * right > 0.0) slopes_[i] = 2.0 * left * right / (left + right);
  }
  slopes_[0] = 1.5 * secant[0] - 0.5 * slopes_[1];
  slopes_[n - 1] = 1.5 * secant[n - 2] - 0.5 * slopes_[n - 2];
}

std::size_t ConstrainedSpline::interval(double x) const {
  const auto above = std::upper_bound(x_.begin(), x_.end(), x);
  const auto k = static_cast<std::size_t>(std::max<std::ptrdiff_t>(above - x_.begin() - 1, 0));
  return std::min(k, x_.size() - 2);
}

double ConstrainedSpline::evaluate(double x) const {
  if (x <= x_.front()) return y_.front() + slopes_.front() * (x - x_.front());
  if (x >= x_.back()) return y_.back() + slopes_.back() * (x - x_.back());
  const std::size_t k = interval(x);
  const double h = x_[k + 1] - x_[k];
  const double s = (x - x_[k]) / h;
  const double s2 = s * s;
  const double s3 = s2 * s;
  // Cubic Hermite basis on [0, 1].
  return (2.0 * s3 - 3.0 * s2 + 1.0) * y_[k] + (s3 - 2.0 * s2 + s) * h * slopes_[k] +
         (3.0 * s2 - 2.0 * s3) * y_[k + 1] + (s3 - s2) * h * slopes_[k + 1];
}

double ConstrainedSpline::derivative(double x) const {
  if (x <= x_.front()) return slopes_.front();
  if (x >= x_.back()) return slopes_.back();
  const std::size_t k = interval(x);
  const double h = x_[k + 1] - x_[k];
  const double s = (x - x_[k]) / h;
  const double s2 = s * s;
  return (6.0 * s2 - 6.0 * s) * (y_[k] - y_[k + 1]) / h + (3.0 * s2 - 4.0 * s + 1.0) * slopes_[k] +
         (3.0 * s2 - 2.0 * s) * slopes_[k + 1];
}

}  // namespace mmm::fibres

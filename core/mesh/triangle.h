#pragma once
// Small per-triangle predicates shared by the differential operators.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace mmm::mesh {

// True when `double_area` (twice the area of triangle p[0], p[1], p[2]) is
// below what rounding can tell from zero. The edge vectors carry an absolute
// error of about eps * |p| (coordinates far from the origin lose low bits), so
// the cross product is only known to about eps * longest * (longest + |p|);
// eight ulps of that is "zero area".
inline bool is_numerically_degenerate(const std::array<Eigen::Vector3d, 3>& p, double double_area) {
  const double longest = std::sqrt(std::max(
      {(p[1] - p[0]).squaredNorm(), (p[2] - p[1]).squaredNorm(), (p[0] - p[2]).squaredNorm()}));
  const double magnitude = std::max(
      {p[0].cwiseAbs().maxCoeff(), p[1].cwiseAbs().maxCoeff(), p[2].cwiseAbs().maxCoeff()});
  return double_area <=
         8.0 * std::numeric_limits<double>::epsilon() * longest * (longest + magnitude);
}

}  // namespace mmm::mesh

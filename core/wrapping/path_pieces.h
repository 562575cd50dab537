#pragma once
// Pieces shared by the path computations of core/wrapping/ (obstacle_set.cpp,
// ellipsoid_geodesic.cpp, global_path.cpp): the result for a segment that does
// not wrap, and the length of a polyline. Not part of the public contract.

#include <Eigen/Core>
#include <cstddef>
#include <span>

#include "core/wrapping/obstacle_set.h"

namespace mmm::wrapping::detail {

// The path P -> S as the plain segment (not wrapped; `inside`: P or S lies
// inside the obstacle).
inline WrapResult straight(const Eigen::Vector3d& p, const Eigen::Vector3d& s, bool inside) {
  WrapResult result;
  result.inside = inside;
  result.length = (s - p).norm();
  result.points = {p, s};
  return result;
}

// The sum of the segment lengths (0 for fewer than two points).
inline double polyline_length(std::span<const Eigen::Vector3d> points) {
  double length = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

}  // namespace mmm::wrapping::detail

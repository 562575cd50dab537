#pragma once
// Small helpers shared by test files (header-only: the tests of one folder are
// compiled together, so a helper used by several of them lives here once).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.h"

namespace mmm::test {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The message of the IoError `call` throws; "" when it throws nothing.
template <typename F>
std::string io_error_of(F&& call) {
  try {
    call();
  } catch (const IoError& error) {
    return error.what();
  }
  return {};
}

// Sum of the segment lengths of a polyline.
inline double polyline_length(const std::vector<Eigen::Vector3d>& points) {
  double length = 0;
  for (std::size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

// A pose at `translation`, turned by 0.4 rad about (1, 1, 0): no axis of it
// lies along a world axis.
inline Eigen::Isometry3d tilted_pose(const Eigen::Vector3d& translation) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = translation;
  pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 0).normalized()).matrix();
  return pose;
}

}  // namespace mmm::test

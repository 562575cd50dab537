#pragma once
// Least-squares ellipsoid through points of a surface patch: centre, principal
// axes and semi-axes. Used for the wrap surfaces the atlas build fits to bone
// regions (the calcaneus, the pelvic brim, ...).
//
//   start: the points' mean and principal axes; semi-axes from the spread
//     along each (sqrt(3) sigma: exact for points spread evenly over a whole
//     ellipsoid), or a given start
//   parameters: centre c, a small rotation w of the start axes, log of the
//     three semi-axes (kept positive)
//   residual: the distance from p to the ellipsoid along the ray from the
//     centre, |q| (1 - 1/k) with q = R^T (p - c), k = |q ./ semi-axes| (exact
//     for a sphere, a close stand-in for the orthogonal distance of a surface
//     patch near the ellipsoid), Levenberg-Marquardt (Ceres)
// A patch covering little of the ellipsoid leaves its far side free: the fit
// is only as good as the patch (the report's rms says how well it fits the
// points, not how well the rest is determined).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace mmm::fit {

struct EllipsoidFitResult {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();     // mm
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();   // columns: principal directions (rotation)
  Eigen::Vector3d semi_axes = Eigen::Vector3d::Ones();  // along each column of `axes` (mm)
  double rms = 0;  // RMS ray distance of the points to the ellipsoid (mm)
  bool converged = false;
};

struct EllipsoidStart {
  Eigen::Vector3d centre;
  Eigen::Matrix3d axes;  // a rotation
  Eigen::Vector3d semi_axes;
};

// Fits an ellipsoid to `points` (#P by 3, mm, #P >= 9). Throws
// InvalidInputError for fewer than 9 points, a non-finite coordinate, or
// points in a plane; SolverError when the fit gives non-finite numbers.
EllipsoidFitResult ellipsoid_fit(const Eigen::MatrixX3d& points,
                                 const std::optional<EllipsoidStart>& start = std::nullopt);

}  // namespace mmm::fit

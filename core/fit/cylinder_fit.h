#pragma once
// Least-squares circular cylinder through points of a surface patch: the axis
// (a point and a direction) and the radius minimising the sum of squared
// distances from the points to the cylinder. Used for the wrap surfaces the
// atlas build fits to bone regions (femoral condyles, ...).
//
//   frame R0: z along the start axis (a hint, e.g. a joint's axis, or the
//     points' direction of least curvature); centre c0 the points' mean
//   parameters (a_x, a_y, u, v, r): the axis turned by the small rotation
//     exp([a_x, a_y, 0]) of R0's x and y (no turn about the axis itself, which
//     changes nothing) through c0 + R (u, v, 0), radius r
//   residual e_i = |(q_i)_xy| - r with q_i = R^T (p_i - c) (the exact
//     orthogonal distance), Levenberg-Marquardt (Ceres); the start radius is
//     the mean distance of the points from the start axis
// The axis point is reported as the point of the axis nearest the points'
// mean, and the length as the points' extent along the axis.

#include <Eigen/Core>
#include <optional>

namespace mmm::fit {

struct CylinderFitResult {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // on the axis, mid-extent of the points (mm)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // unit; its sign follows the hint
  double radius = 0;                                 // mm
  double length = 0;                                 // extent of the points along the axis (mm)
  double rms = 0;  // RMS distance of the points to the cylinder (mm)
  bool converged = false;
};

// Fits a cylinder to `points` (#P by 3, mm, #P >= 5), starting from the axis
// direction `axis_hint` when given (else the principal direction of the
// points along which they vary least in curvature: the one of largest
// spread). Throws InvalidInputError for fewer than 5 points, a non-finite
// coordinate or a zero hint; SolverError when the fit gives non-finite
// numbers.
CylinderFitResult cylinder_fit(const Eigen::MatrixX3d& points,
                               const std::optional<Eigen::Vector3d>& axis_hint = std::nullopt);

}  // namespace mmm::fit

#include "core/fit/cylinder_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "core/errors.h"
#include "core/fit/dense_least_squares.h"

namespace mmm::fit {
namespace {

// A start frame whose z is `axis` (unit).
Eigen::Matrix3d frame_along(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d x = axis.unitOrthogonal();
  Eigen::Matrix3d frame;
  frame.col(0) = x;
  frame.col(1) = axis.cross(x);
  frame.col(2) = axis;
  return frame;
}

// Distance of one point (in the start frame, relative to the start centre)
// to the cylinder of parameters (a_x, a_y, u, v, r).
struct CylinderResidual {
  explicit CylinderResidual(Eigen::Vector3d s) : s_(std::move(s)) {}

  template <typename T>
  bool operator()(const T* const x, T* residual) const {
    const std::array<T, 3> minus_turn{-x[0], -x[1], T(0)};
    const std::array<T, 3> s{T(s_.x()), T(s_.y()), T(s_.z())};
    std::array<T, 3> q{};
    ceres::AngleAxisRotatePoint(minus_turn.data(), s.data(), q.data());
    const T dx = q[0] - x[2];
    const T dy = q[1] - x[3];
    const T squared = dx * dx + dy * dy;
    // On the axis the distance does not depend on the axis to first order.
    residual[0] = (squared > T(1e-24) ? ceres::sqrt(squared) : T(0)) - x[4];
    return true;
  }

 private:
  Eigen::Vector3d s_;
};

}  // namespace

CylinderFitResult cylinder_fit(const Eigen::MatrixX3d& points,
                               const std::optional<Eigen::Vector3d>& axis_hint) {
  if (points.rows() < 5) {
    throw InvalidInputError("cylinder_fit: needs at least 5 points, got " +
                            std::to_string(points.rows()));
  }
  if (!points.allFinite()) throw InvalidInputError("cylinder_fit: a point is not finite");
  if (axis_hint && !(axis_hint->allFinite() && axis_hint->norm() > 0)) {
    throw InvalidInputError("cylinder_fit: the axis hint is zero or not finite");
  }
  const Eigen::Vector3d mean = points.colwise().mean().transpose();
  const Eigen::MatrixX3d centred = points.rowwise() - mean.transpose();
  Eigen::Vector3d axis;
  if (axis_hint) {
    axis = axis_hint->normalized();
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(centred.transpose() * centred);
    axis = solver.eigenvectors().col(2);  // largest spread
  }
  const Eigen::Matrix3d start = frame_along(axis);
  const Eigen::MatrixX3d local = centred * start;  // rows: R0^T (p - mean)

  // Start: the axis through the centre of the points' circle in the plane
  // across the hint (Kasa fit of the projections), radius their mean distance.
  Eigen::MatrixX3d a(points.rows(), 3);
  a.col(0) = 2.0 * local.col(0);
  a.col(1) = 2.0 * local.col(1);
  a.col(2).setOnes();
  const Eigen::VectorXd b = local.leftCols<2>().rowwise().squaredNorm();
  const Eigen::Vector3d circle = a.colPivHouseholderQr().solve(b);
  std::array<double, 5> x{0, 0, circle.x(), circle.y(), 0};
  if (!std::isfinite(x[2]) || !std::isfinite(x[3])) x[2] = x[3] = 0;
  double mean_distance = 0;
  for (Eigen::Index i = 0; i < local.rows(); ++i) {
    mean_distance += std::hypot(local(i, 0) - x[2], local(i, 1) - x[3]);
  }
  x[4] = mean_distance / static_cast<double>(local.rows());

  ceres::Problem problem;
  for (Eigen::Index i = 0; i < local.rows(); ++i) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CylinderResidual, 1, 5>(
                                 new CylinderResidual(local.row(i).transpose())),
                             nullptr, x.data());
  }
  const ceres::Solver::Options options = detail::dense_least_squares_options(200);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  const Eigen::Vector3d turn_vector(x[0], x[1], 0);
  const double angle = turn_vector.norm();
  const Eigen::Matrix3d turn =
      angle > 0 ? Eigen::AngleAxisd(angle, turn_vector / angle).toRotationMatrix()
                : Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d frame = start * turn;
  CylinderFitResult result;
  result.axis = frame.col(2);
  result.radius = std::abs(x[4]);
  const Eigen::Vector3d through = mean + frame * Eigen::Vector3d(x[2], x[3], 0);
  const Eigen::VectorXd along = (points.rowwise() - through.transpose()) * result.axis;
  const double low = along.minCoeff();
  const double high = along.maxCoeff();
  result.length = high - low;
  result.centre = through + 0.5 * (low + high) * result.axis;
  double squared = 0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d d = points.row(i).transpose() - through;
    const double e = (d - d.dot(result.axis) * result.axis).norm() - result.radius;
    squared += e * e;
  }
  result.rms = std::sqrt(squared / static_cast<double>(points.rows()));
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  if (!result.centre.allFinite() || !result.axis.allFinite() || !std::isfinite(result.radius)) {
    throw SolverError("cylinder_fit: the fit gave non-finite numbers");
  }
  return result;
}

}  // namespace mmm::fit

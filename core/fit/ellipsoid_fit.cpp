#include "core/fit/ellipsoid_fit.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "core/errors.h"
#include "core/fit/dense_least_squares.h"

namespace mmm::fit {
namespace {

// Variance across the thinnest direction below this fraction of that along
// the widest: the points lie in a plane (see sphere_fit.cpp).
constexpr double kFlatEllipsoidVarianceRatio = 1e-12;

// Ray distance of one point (start frame, relative to the start centre) to
// the ellipsoid of parameters: centre (3), small turn (3), log semi-axes (3).
struct EllipsoidResidual {
  explicit EllipsoidResidual(Eigen::Vector3d s) : s_(std::move(s)) {}

  template <typename T>
  bool operator()(const T* const centre, const T* const turn, const T* const log_semi,
                  T* residual) const {
    const std::array<T, 3> d{T(s_.x()) - centre[0], T(s_.y()) - centre[1], T(s_.z()) - centre[2]};
    const std::array<T, 3> minus_turn{-turn[0], -turn[1], -turn[2]};
    std::array<T, 3> q{};
    ceres::AngleAxisRotatePoint(minus_turn.data(), d.data(), q.data());
    const T length_squared = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
    T scaled_squared(0);
    for (int k = 0; k < 3; ++k) {
      const T t = q[k] / ceres::exp(log_semi[k]);
      scaled_squared += t * t;
    }
    if (length_squared < T(1e-24)) {
      // At the centre: as far inside as the shortest semi-axis.
      T shortest = ceres::exp(log_semi[0]);
      for (int k = 1; k < 3; ++k) {
        const T semi = ceres::exp(log_semi[k]);
        if (semi < shortest) shortest = semi;
      }
      residual[0] = -shortest;
      return true;
    }
    const T length = ceres::sqrt(length_squared);
    residual[0] = length - length / ceres::sqrt(scaled_squared);
    return true;
  }

 private:
  Eigen::Vector3d s_;
};

Eigen::Matrix3d rotation_of(const std::array<double, 3>& turn) {
  const Eigen::Vector3d w(turn[0], turn[1], turn[2]);
  const double angle = w.norm();
  return angle > 0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                   : Eigen::Matrix3d::Identity();
}

}  // namespace

EllipsoidFitResult ellipsoid_fit(const Eigen::MatrixX3d& points,
                                 const std::optional<EllipsoidStart>& start) {
  if (points.rows() < 9) {
    throw InvalidInputError("ellipsoid_fit: needs at least 9 points, got " +
                            std::to_string(points.rows()));
  }
  if (!points.allFinite()) throw InvalidInputError("ellipsoid_fit: a point is not finite");
  const Eigen::Vector3d mean = points.colwise().mean().transpose();
  const Eigen::MatrixX3d centred = points.rowwise() - mean.transpose();
  const Eigen::Matrix3d covariance =
      centred.transpose() * centred / static_cast<double>(points.rows());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d variance = solver.eigenvalues().cwiseMax(0.0);  // ascending
  if (!(variance[0] >= kFlatEllipsoidVarianceRatio * variance[2])) {
    throw InvalidInputError(
        "ellipsoid_fit: the points lie in a plane, so no ellipsoid fits them; hint: take a "
        "curved surface patch");
  }
  EllipsoidStart from;
  if (start) {
    from = *start;
    if (!from.centre.allFinite() || !from.axes.allFinite() || !(from.semi_axes.array() > 0).all()) {
      throw InvalidInputError("ellipsoid_fit: the start is not finite or has a semi-axis <= 0");
    }
  } else {
    from.centre = mean;
    from.axes = solver.eigenvectors();
    if (from.axes.determinant() < 0) from.axes.col(0) *= -1.0;
    from.semi_axes = (3.0 * variance).cwiseSqrt();
  }
  const Eigen::MatrixX3d local = (points.rowwise() - from.centre.transpose()) * from.axes;

  std::array<double, 3> centre{0, 0, 0};
  std::array<double, 3> turn{0, 0, 0};
  std::array<double, 3> log_semi{std::log(from.semi_axes.x()), std::log(from.semi_axes.y()),
                                 std::log(from.semi_axes.z())};
  ceres::Problem problem;
  for (Eigen::Index i = 0; i < local.rows(); ++i) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<EllipsoidResidual, 1, 3, 3, 3>(
                                 new EllipsoidResidual(local.row(i).transpose())),
                             nullptr, centre.data(), turn.data(), log_semi.data());
  }
  const ceres::Solver::Options options = detail::dense_least_squares_options(300);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  EllipsoidFitResult result;
  result.centre = from.centre + from.axes * Eigen::Vector3d(centre[0], centre[1], centre[2]);
  result.axes = from.axes * rotation_of(turn);
  result.semi_axes =
      Eigen::Vector3d(std::exp(log_semi[0]), std::exp(log_semi[1]), std::exp(log_semi[2]));
  double squared = 0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d q = result.axes.transpose() * (points.row(i).transpose() - result.centre);
    const double k = q.cwiseQuotient(result.semi_axes).norm();
    const double e = k > 0 ? q.norm() * (1.0 - 1.0 / k) : -result.semi_axes.minCoeff();
    squared += e * e;
  }
  result.rms = std::sqrt(squared / static_cast<double>(points.rows()));
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  if (!result.centre.allFinite() || !result.axes.allFinite() || !result.semi_axes.allFinite()) {
    throw SolverError("ellipsoid_fit: the fit gave non-finite numbers");
  }
  return result;
}

}  // namespace mmm::fit

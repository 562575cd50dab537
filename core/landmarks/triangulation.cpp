#include "core/landmarks/triangulation.h"

#include <ceres/ceres.h>

#include <array>
#include <cmath>
#include <memory>
#include <utility>

#include "core/errors.h"

namespace mmm::landmarks {

namespace {

// Residual of one view: (projection - observed pixel) * pixel spacing (mm).
struct ReprojectionResidual {
  ReprojectionResidual(Eigen::Matrix<double, 3, 4> P, Eigen::Vector2d pixel, double spacing_mm,
                       double depth_sign, bool slot_scanning)
      : P_(std::move(P)),
        pixel_(std::move(pixel)),
        spacing_mm_(spacing_mm),
        depth_sign_(depth_sign),
        slot_scanning_(slot_scanning) {}

  template <typename T>
  bool operator()(const T* const X, T* residual) const {
    std::array<T, 3> h;
    for (int r = 0; r < 3; ++r) {
      h[r] = T(P_(r, 0)) * X[0] + T(P_(r, 1)) * X[1] + T(P_(r, 2)) * X[2] + T(P_(r, 3));
    }
    // A point on or behind the plane of the source casts no shadow: tell
    // Ceres the step is infeasible so that it shortens it.
    if (!(h[2] * T(depth_sign_) > T(0))) return false;
    residual[0] = (h[0] / h[2] - T(pixel_.x())) * T(spacing_mm_);
    // A slot-scanning view's row is affine in X (projection.h).
    const T v = slot_scanning_ ? h[1] : h[1] / h[2];
    residual[1] = (v - T(pixel_.y())) * T(spacing_mm_);
    return true;
  }

 private:
  Eigen::Matrix<double, 3, 4> P_;
  Eigen::Vector2d pixel_;
  double spacing_mm_;
  double depth_sign_;
  bool slot_scanning_;
};

void check_options(const TriangulationOptions& options) {
  if (options.max_iterations < 1) {
    throw InvalidInputError("TriangulationOptions.max_iterations must be >= 1, got " +
                            std::to_string(options.max_iterations));
  }
  for (const double tolerance :
       {options.function_tolerance, options.gradient_tolerance, options.parameter_tolerance}) {
    if (!std::isfinite(tolerance) || tolerance < 0) {
      throw InvalidInputError("TriangulationOptions: tolerances must be finite numbers >= 0, got " +
                              std::to_string(tolerance));
    }
  }
}

}  // namespace

Triangulation triangulate(std::span<const image::RadiographView> views,
                          std::span<const Eigen::Vector2d> pixels,
                          const TriangulationOptions& options) {
  check_options(options);
  Triangulation result;
  // Validates the views and pixels and rejects degenerate geometry.
  result.linear_point_mm = image::triangulate_linear(views, pixels);

  std::array<double, 3> X = {result.linear_point_mm.x(), result.linear_point_mm.y(),
                             result.linear_point_mm.z()};
  ceres::Problem problem;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const image::RadiographView& view = views[i];
    const double sign = view.P.leftCols<3>().determinant() > 0 ? 1.0 : -1.0;
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<ReprojectionResidual, 2, 3>(
            new ReprojectionResidual(view.P, pixels[i], view.pixel_spacing_mm, sign,
                                     view.model == image::ProjectionModel::kSlotScanning)),
        nullptr, X.data());
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  result.solver_report = summary.BriefReport();
  result.termination = ceres::TerminationTypeToString(summary.termination_type);
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;  // entry 0 is the start
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.point_mm = Eigen::Vector3d(X[0], X[1], X[2]);
  if (summary.termination_type == ceres::FAILURE ||
      summary.termination_type == ceres::USER_FAILURE || !result.point_mm.allFinite()) {
    throw SolverError("triangulate: Ceres did not reach a usable point: " + result.solver_report);
  }

  double sum_squares = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const double error = image::reprojection_error_mm(views[i], result.point_mm, pixels[i]);
    result.reprojection_error_mm.push_back(error);
    sum_squares += error * error;
  }
  result.rms_error_mm = std::sqrt(sum_squares / static_cast<double>(views.size()));
  return result;
}

}  // namespace mmm::landmarks

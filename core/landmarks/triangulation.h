#pragma once
// Triangulation of one landmark seen in N >= 2 calibrated radiographs
// (core/image/projection.h): the point X (mm, patient frame) whose
// projections lie closest to the operator's pixels, errors measured in mm at
// the isocentre plane so that views of different resolution weigh what they
// are worth.
//
//   X0 = triangulate_linear(views, pixels)          (linear start, Hartley & Sturm 1997)
//   minimise over X  1/2 sum_i |s_i (pi_i(X) - p_i)|^2
//     pi_i(X) = (P_i [X 1]) dehomogenised, s_i = pixel spacing of view i (mm/pixel),
//     Levenberg-Marquardt (Ceres, automatic derivatives), X must stay in front of
//     every source
// The minimiser is the maximum-likelihood point under isotropic Gaussian
// click noise of equal size in mm in every view (the "gold standard" of
// Hartley & Zisserman, "Multiple View Geometry", 2nd ed., sec. 12.1); the
// linear start is close to it but minimises an algebraic error.

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "core/image/projection.h"

namespace mmm::landmarks {

struct TriangulationOptions {
  // Most Levenberg-Marquardt iterations (>= 1). From the linear start a
  // handful suffice; 100 leaves room for poorly conditioned views.
  int max_iterations = 100;
  // Ceres' convergence tolerances (Solver::Options): relative change of the
  // cost, gradient norm, and relative step size. 1e-12 reaches the minimum to
  // rounding (the cost is in mm^2 of at most a few views).
  double function_tolerance = 1e-12;
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
};

struct Triangulation {
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();         // the refined point (mm)
  Eigen::Vector3d linear_point_mm = Eigen::Vector3d::Zero();  // the linear start (mm)
  // Reprojection error of point_mm in each view, same order as the views
  // (mm at the isocentre plane: pixel distance * pixel_spacing_mm).
  std::vector<double> reprojection_error_mm;
  // sqrt(mean of reprojection_error_mm^2) (mm).
  double rms_error_mm = 0;
  // Ceres' cost 1/2 sum of squared residuals (mm^2) at the linear start and
  // at the end; final_cost <= initial_cost.
  double initial_cost = 0;
  double final_cost = 0;
  int iterations = 0;         // Levenberg-Marquardt iterations taken
  bool converged = false;     // Ceres reported CONVERGENCE
  std::string termination;    // Ceres' termination type, e.g. "CONVERGENCE", "NO_CONVERGENCE"
  std::string solver_report;  // Ceres' Summary::BriefReport()
};

// Triangulates the point seen at pixels[i] (u, v) in views[i].
// Throws InvalidInputError for the input triangulate_linear rejects (fewer
// than 2 views, counts that differ, a non-finite pixel, an invalid view,
// degenerate geometry) and for options out of range; SolverError (with
// Ceres' report) when the solver fails or returns a non-finite point. Running
// out of iterations is not an error: the best point is returned with
// converged = false.
Triangulation triangulate(std::span<const image::RadiographView> views,
                          std::span<const Eigen::Vector2d> pixels,
                          const TriangulationOptions& options = {});

}  // namespace mmm::landmarks

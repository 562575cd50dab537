#pragma once
// Solver settings shared by the small dense fits of core/fit/ that use Ceres
// (cylinder_fit.cpp, ellipsoid_fit.cpp): Levenberg-Marquardt on a dense QR,
// tolerances tight enough that exact data are fitted to rounding, silent.
// Not part of the public contract.

#include <ceres/ceres.h>

namespace mmm::fit::detail {

inline ceres::Solver::Options dense_least_squares_options(int max_iterations) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  options.gradient_tolerance = 1e-16;
  options.logging_type = ceres::SILENT;
  return options;
}

}  // namespace mmm::fit::detail

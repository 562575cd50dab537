#pragma once
// The linear least-squares rows of the outline fit (outline_fit.h): each term
// of the energy adds rows `sum coefficient * theta[column] = value` with a
// weight, where theta = (D row-major (9), b (3), t (3 per node)) moves a
// point of the start surface X0 to
//   x(X0) = X0 + D (X0 - c) + b + sum_i w_i(X0) t_i.

#include <Eigen/Core>
#include <utility>
#include <vector>

namespace mmm::outlines {

// The unknowns before the nodes' displacements: D (9, row-major) and b (3).
inline constexpr int kAffineUnknowns = 12;

// Sparse weights of the nodes for a set of points: row i lists (node, w).
using NodeWeights = std::vector<std::vector<std::pair<int, double>>>;

// One linear equation in theta: sum coefficient * theta[column] = value, weight.
struct FitRow {
  std::vector<std::pair<int, double>> terms;
  double value = 0.0;
  double weight = 1.0;
};

// Adds the coefficients of a . x(theta) for a point with rest position `rest`
// and node weights `w`, scaled by `scale`, to `row`; returns a . rest * scale
// (the part of a . x that does not depend on theta).
[[nodiscard]] double add_point(FitRow& row, const Eigen::Vector3d& a, const Eigen::Vector3d& rest,
                               const Eigen::Vector3d& centre,
                               const std::vector<std::pair<int, double>>& w, double scale);

}  // namespace mmm::outlines

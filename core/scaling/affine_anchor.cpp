#include "core/scaling/affine_anchor.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace mmm::scaling {
namespace {

// Rows of an evenly strided subsample of at most `count` vertices: the
// vertices of a mesh are in no particular spatial order, so a stride spreads
// them over the surface well enough for a far point's anchor.
std::vector<int> strided_rows(Eigen::Index rows, Eigen::Index count) {
  std::vector<int> picked;
  const Eigen::Index step = std::max<Eigen::Index>(1, rows / count);
  for (Eigen::Index i = 0; i < rows; i += step) picked.push_back(static_cast<int>(i));
  return picked;
}

Eigen::MatrixX3d rows_of(const Eigen::MatrixX3d& vertices, const std::vector<int>& rows) {
  Eigen::MatrixX3d picked(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    picked.row(static_cast<Eigen::Index>(i)) = vertices.row(rows[i]);
  }
  return picked;
}

constexpr Eigen::Index kSpreadCount = 256;

}  // namespace

AnchorBuilder::AnchorBuilder(const Eigen::MatrixX3d& vertices, int k)
    : grid_(vertices),
      spread_(rows_of(vertices, strided_rows(vertices.rows(), kSpreadCount))),
      spread_rows_(strided_rows(vertices.rows(), kSpreadCount)),
      k_(std::max(4, k)) {}

AffineAnchor AnchorBuilder::anchor(const Eigen::Vector3d& point) const {
  if (!point.allFinite()) throw InvalidInputError("affine anchor: the point is not finite");
  const Eigen::MatrixX3d& vertices = grid_.points();
  // The nearest vertices, and the nearest of a subsample spread over the
  // whole surface: near a surface the nearest form a nearly flat patch that
  // fixes the direction off it badly, and the spread ones (weighted down by
  // their distance) keep the system well conditioned there.
  std::vector<int> rows = grid_.nearest(point, k_);
  for (int row : spread_.nearest(point, k_)) {
    row = spread_rows_[static_cast<std::size_t>(row)];
    if (std::find(rows.begin(), rows.end(), row) == rows.end()) rows.push_back(row);
  }
  const auto k = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd B(4, k);
  double mean_distance = 0.0;
  for (Eigen::Index i = 0; i < k; ++i) {
    B.block<3, 1>(0, i) = vertices.row(rows[static_cast<std::size_t>(i)]).transpose();
    B(3, i) = 1.0;
    mean_distance += (B.block<3, 1>(0, i) - point).norm() / static_cast<double>(k);
  }
  // Centre the coordinates on the point, so the system is well scaled
  // whatever the frame's origin.
  for (Eigen::Index i = 0; i < k; ++i) B.block<3, 1>(0, i) -= point;
  Eigen::VectorXd phi(k);
  const double h2 = std::max(mean_distance * mean_distance, 1e-12);
  for (Eigen::Index i = 0; i < k; ++i) phi[i] = 1.0 / (B.block<3, 1>(0, i).squaredNorm() + h2);
  const Eigen::Matrix4d normal = B * phi.asDiagonal() * B.transpose();
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(normal);
  // Two steps of iterative refinement take the constraint to rounding.
  const Eigen::Vector4d target(0.0, 0.0, 0.0, 1.0);
  Eigen::VectorXd w = phi.asDiagonal() * (B.transpose() * lu.solve(target));
  for (int step = 0; step < 2; ++step) {
    const Eigen::Vector4d residual = target - B * w;
    w += phi.asDiagonal() * (B.transpose() * lu.solve(residual));
  }
  // Coplanar vertices (a flat surface) cannot express a point off their
  // plane: the constraint then fails.
  if (!w.allFinite() || (target - B * w).norm() > 1e-6 * (1.0 + mean_distance)) {
    throw InvalidInputError(
        "affine anchor: the surface's vertices are degenerate (all in one plane?) and cannot "
        "express the point");
  }
  AffineAnchor anchor;
  anchor.vertices = std::move(rows);
  anchor.weights.assign(w.data(), w.data() + w.size());
  return anchor;
}

Eigen::Vector3d reconstruct(const AffineAnchor& anchor, const Eigen::MatrixX3d& vertices) {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < anchor.vertices.size(); ++i) {
    point += anchor.weights[i] * vertices.row(anchor.vertices[i]).transpose();
  }
  return point;
}

}  // namespace mmm::scaling

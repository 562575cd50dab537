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
      k_(std::max(4, k)) {
  // Typical vertex spacing, from a few vertices' nearest neighbours.
  std::vector<double> gaps;
  for (const int row : strided_rows(vertices.rows(), 64)) {
    const std::vector<int> two = grid_.nearest(vertices.row(row).transpose(), 2);
    if (two.size() == 2) gaps.push_back((vertices.row(two[1]) - vertices.row(row)).norm());
  }
  if (!gaps.empty()) {
    std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2),
                     gaps.end());
    spacing_mm_ = std::max(1e-6, gaps[gaps.size() / 2]);
  }
}

AffineAnchor AnchorBuilder::anchor(const Eigen::Vector3d& point) const {
  if (!point.allFinite()) throw InvalidInputError("affine anchor: the point is not finite");
  const Eigen::MatrixX3d& vertices = grid_.points();
  std::vector<int> rows = grid_.nearest(point, k_);
  // Far from the surface (more than a few vertex spacings) the nearest
  // vertices form a flat patch that fixes the normal direction badly: take
  // the nearest of a subsample spread over the whole surface instead.
  const double gap = (vertices.row(rows.front()).transpose() - point).norm();
  if (gap > 4.0 * spacing_mm_) {
    rows = spread_.nearest(point, k_);
    for (int& row : rows) row = spread_rows_[static_cast<std::size_t>(row)];
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
  Eigen::Matrix4d normal = B * phi.asDiagonal() * B.transpose();
  normal.diagonal().array() += 1e-12 * normal.trace();
  Eigen::Vector4d target(0.0, 0.0, 0.0, 1.0);
  const Eigen::Vector4d lambda = normal.ldlt().solve(target);
  const Eigen::VectorXd w = phi.asDiagonal() * (B.transpose() * lambda);
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

#pragma once
// The k vertices nearest a query point, from a uniform grid over a point set:
// cells of about `points_per_cell` points, searched in growing shells until
// the k-th distance found is below the distance to the unsearched shells.
// Exact (the same answer as a full sort), O(k + cells visited) per query.

#include <Eigen/Core>
#include <vector>

namespace mmm::mesh {

class VertexGrid {
 public:
  // `points` #P by 3 (mm), finite. Throws InvalidInputError on an empty set or
  // a non-finite coordinate. Keeps a copy.
  explicit VertexGrid(const Eigen::MatrixX3d& points, double points_per_cell = 8.0);

  // Rows of the k points nearest `query`, nearest first (fewer when the set
  // is smaller than k). Const and thread-safe.
  [[nodiscard]] std::vector<int> nearest(const Eigen::Vector3d& query, int k) const;

  [[nodiscard]] const Eigen::MatrixX3d& points() const { return points_; }

 private:
  [[nodiscard]] Eigen::Vector3i cell_of(const Eigen::Vector3d& point) const;

  Eigen::MatrixX3d points_;
  Eigen::Vector3d origin_;
  double cell_size_ = 1.0;
  Eigen::Vector3i dims_;
  std::vector<int> cell_start_;  // CSR: cell c holds order_[cell_start_[c] .. cell_start_[c+1])
  std::vector<int> order_;
};

}  // namespace mmm::mesh

#pragma once
// A point tied to a surface by an affine combination of its vertices:
//   p = sum_i w_i v_i,  sum_i w_i = 1
// so that after any deformation of the surface the point is reconstructed
// as sum_i w_i v'_i. This is how every element derived from a bone or muscle
// (landmarks, markers, joint centres, action-line points, attachment
// centroids, wrap-obstacle centres, the vertices of the coarser levels of
// detail) follows its surface through scaling: exact for every affine map of
// the surface (the affine combination commutes with it), and for a smooth
// non-affine deformation the point moves as the surface around it does.
//
// Weights: over the k vertices nearest p and the k nearest p of a subsample
// spread over the whole surface (near the surface the nearest vertices form
// a nearly flat patch, which alone would fix the direction off it badly),
// the weighted minimum-norm solution
//   min sum_i w_i^2 / phi_i  subject to  B w = (p, 1),  phi_i = 1 / (|v_i - p|^2 + h^2)
// (B the 4 x m matrix of homogeneous vertex positions, h the mean distance
// of the m vertices), i.e. w = Phi B^T (B Phi B^T)^-1 (p, 1): the nearest
// vertices carry the most weight; two steps of iterative refinement take the
// constraint to rounding.

#include <Eigen/Core>
#include <vector>

#include "core/mesh/vertex_grid.h"

namespace mmm::scaling {

struct AffineAnchor {
  std::vector<int> vertices;
  std::vector<double> weights;  // sum to 1
};

// Builds anchors on one surface, given its vertices.
class AnchorBuilder {
 public:
  explicit AnchorBuilder(const Eigen::MatrixX3d& vertices, int k = 16);

  // Throws InvalidInputError for a non-finite point.
  [[nodiscard]] AffineAnchor anchor(const Eigen::Vector3d& point) const;

  [[nodiscard]] const mesh::VertexGrid& grid() const { return grid_; }

 private:
  mesh::VertexGrid grid_;
  mesh::VertexGrid spread_;       // over a subsample of the vertices
  std::vector<int> spread_rows_;  // its rows -> vertex rows
  int k_ = 16;
};

// sum_i w_i V.row(vertices_i).
Eigen::Vector3d reconstruct(const AffineAnchor& anchor, const Eigen::MatrixX3d& vertices);

}  // namespace mmm::scaling

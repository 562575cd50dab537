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
// Weights: the k vertices nearest p (on the whole surface for points far
// from it, whose nearest vertices would be a nearly flat patch, k from a
// spread subsample), with the weighted minimum-norm solution
//   min sum_i w_i^2 / phi_i  subject to  B w = (p, 1),  phi_i = 1 / (|v_i - p|^2 + h^2)
// (B the 4 x k matrix of homogeneous vertex positions, h the mean distance
// of the k vertices), i.e. w = Phi B^T (B Phi B^T)^-1 (p, 1): the nearest
// vertices carry the most weight. A tiny ridge (1e-12 of the trace) keeps a
// perfectly flat patch solvable; the constraint then holds to ~1e-9 mm.

#include <Eigen/Core>
#include <vector>

#include "core/mesh/vertex_grid.h"

namespace mmm::scaling {

struct AffineAnchor {
  std::vector<int> vertices;
  std::vector<double> weights;  // sum to 1
};

// Builds anchors on one surface (its vertices `grid.points()`); `spread` is a
// grid over a subsample spread over the same surface, with `spread_rows`
// mapping its rows to the surface's vertex rows.
class AnchorBuilder {
 public:
  explicit AnchorBuilder(const Eigen::MatrixX3d& vertices, int k = 16);

  // Throws InvalidInputError for a non-finite point.
  [[nodiscard]] AffineAnchor anchor(const Eigen::Vector3d& point) const;

  [[nodiscard]] const mesh::VertexGrid& grid() const { return grid_; }

 private:
  mesh::VertexGrid grid_;
  mesh::VertexGrid spread_;
  std::vector<int> spread_rows_;
  double spacing_mm_ = 1.0;  // median distance to the nearest other vertex
  int k_ = 16;
};

// sum_i w_i V.row(vertices_i).
Eigen::Vector3d reconstruct(const AffineAnchor& anchor, const Eigen::MatrixX3d& vertices);

}  // namespace mmm::scaling

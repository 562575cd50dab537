#pragma once
// How far apart two surfaces are: the distance from every vertex of each
// surface to the other surface (closest point on its triangles, AabbTree),
// pooled over both directions (symmetric), each vertex weighted by its area
// (a third of the area of its faces, mass_matrix.h) so that a finely meshed region does not
// count more than a coarse one. Mean, 95th percentile and maximum (the
// symmetric Hausdorff distance at the vertices). Used to measure a scaled or
// deformed surface against its ground truth.

#include <Eigen/Core>

#include "core/mesh/aabb_tree.h"
#include "core/mesh/mesh.h"

namespace mmm::mesh {

struct SurfaceDistance {
  double mean_mm = 0;
  double p95_mm = 0;  // area-weighted 95th percentile
  double max_mm = 0;
  Eigen::Index samples = 0;  // vertices measured (both surfaces)
};

// Distance from each row of `points` to the surface of `surface` (mm).
Eigen::VectorXd distances_to_surface(const Eigen::MatrixX3d& points, const AabbTree& surface);

// Symmetric area-weighted distance between `a` and `b`. Throws
// InvalidInputError (from AabbTree) for an empty or non-finite mesh.
SurfaceDistance surface_distance(const IndexedMesh& a, const IndexedMesh& b);

}  // namespace mmm::mesh

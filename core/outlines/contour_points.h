#pragma once
// Points of a closed surface's contour generator as an X-ray source sees it:
// where the surface turns from facing the source to facing away, whose
// projections are the outline of the bone on the radiograph.
//
// With vertex normals N_i (area-weighted face normals) and s the focal spot,
// g_i = N_i . (x_i - s) changes sign across the contour. On every edge (i, j)
// with g_i g_j < 0 the contour crosses at x = (1 - t) x_i + t x_j, t = g_i /
// (g_i - g_j), with normal N = (1 - t) N_i + t N_j. Its projection p and the
// projection of N (through the Jacobian of the projection at x) give the
// outward direction n of the outline in the image: moving the surface along
// N moves the outline along n. Points whose normal projects to less than
// 0.2 of its length (the surface seen almost head-on: a noisy crossing) are
// skipped.

#include <Eigen/Core>
#include <vector>

#include "core/image/projection.h"
#include "core/mesh/mesh.h"

namespace mmm::outlines {

struct ContourPoint {
  int vertex_a = 0;  // edge end points (rows of the mesh's V)
  int vertex_b = 0;
  double t = 0.0;                                      // position along the edge: (1 - t) a + t b
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // mm
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  Eigen::Vector2d outward = Eigen::Vector2d::Zero();  // unit, image plane
};

using image::projection_jacobian;

// Contour points of `surface` (closed, outward-oriented) seen from `view`'s
// source; vertices behind the source plane give none.
std::vector<ContourPoint> contour_points(const mesh::IndexedMesh& surface,
                                         const image::RadiographView& view);

}  // namespace mmm::outlines

#pragma once
// The silhouette of a triangle mesh seen from an X-ray source, as edges and
// as chained polylines in pixel coordinates (what outline_overlay.h draws,
// and what the outline review station shows the operator).
//
//   side:      every face f gets s_f = sign(n_f . (c_f - s)), n_f its
//              (unnormalised) normal, c_f its centroid, s the source:
//              < 0 front-facing, > 0 back-facing as seen from the source
//   edges:     an edge is on the silhouette when its faces include a front-
//              and a back-facing one (the contour generator of a closed
//              surface) or when it has one face only (a boundary); found by
//              sorting the 3 #F corner pairs, O(#F log #F)
//   pieces:    connected pieces (sharing vertices, union-find) of fewer than
//              min_contour_edges edges are dropped (noise of a coarse mesh
//              turning edge-on), the mesh's largest piece never
//   polylines: the kept edges chained end to end: a chain runs between
//              vertices where it cannot continue unambiguously (degree != 2);
//              a closed loop repeats its first point at the end
//
// Meshes must be consistently oriented: a flipped face makes a 3-edge loop of
// its own (dropped, like other small fragments, by min_contour_edges).

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "core/image/projection.h"
#include "core/mesh/mesh.h"

namespace mmm::image {

// Indices into V of the edges of the silhouette of `surface` seen from
// `source` (mm, the mesh's frame), each once, ordered by (low, high) index.
std::vector<std::array<int, 2>> silhouette_edges(const mesh::IndexedMesh& surface,
                                                 const Eigen::Vector3d& source);
// The same seen in `view`: each face from the focal spot that lights it
// (source_for: one spot for a pinhole, the spot at the face's height for a
// slot-scanning view).
std::vector<std::array<int, 2>> silhouette_edges(const mesh::IndexedMesh& surface,
                                                 const RadiographView& view);

// The edges that belong to connected pieces of at least `min_edges` edges,
// or to the largest pieces, in their input order; all of them for
// min_edges <= 1.
std::vector<std::array<int, 2>> keep_contour_pieces(const std::vector<std::array<int, 2>>& edges,
                                                    int min_edges);

// The pixel of every vertex used by a face (zero for the others). Throws
// InvalidInputError, starting with `what`, naming the view and the vertex,
// for a vertex on or behind the source plane.
std::vector<Eigen::Vector2d> project_face_vertices(const RadiographView& view,
                                                   const mesh::IndexedMesh& surface,
                                                   const std::string& what);

// A polyline in pixel coordinates (u right, v down, pixel centres at +0.5).
using Polyline2d = std::vector<Eigen::Vector2d>;

// The silhouette of `surface` in `view` (see the file comment), chained into
// polylines of >= 2 points, projected with the view's P; deterministic (the
// same mesh and view give the same polylines in the same order). An empty
// mesh gives none. Throws InvalidInputError for a view failing validate_view,
// a face index out of range, a non-finite coordinate, a vertex on or behind
// the source plane (the view and vertex are named) or min_contour_edges < 1.
std::vector<Polyline2d> silhouette_polylines(const mesh::IndexedMesh& surface,
                                             const RadiographView& view, int min_contour_edges = 8);

}  // namespace mmm::image

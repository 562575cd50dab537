#pragma once
// Isotropic remeshing: a new triangulation of the same surface whose edges all
// have about one prescribed length. Used to make lower-resolution (or evenly
// resolved) models of bones and muscles.

#include "core/mesh/mesh.h"

namespace mmm::mesh {

struct RemeshOptions {
  // Edge length to aim for (mm), > 0. Edges end up roughly in
  // [4/5, 4/3] * target_edge_length.
  double target_edge_length = 0.0;
  // Rounds of split / collapse / flip / relax / project, >= 1. Five is the
  // usual choice of Botsch & Kobbelt; more rounds smooth the sizes further.
  int iterations = 5;
};

// Uniform isotropic remeshing (Botsch & Kobbelt 2004, "A remeshing approach
// to multiresolution modeling"). Each round: split edges longer than 4/3 L,
// collapse edges shorter than 4/5 L (unless that would create an edge longer
// than 4/3 L or turn a face over), flip edges towards valence 6 (4 on the
// boundary), move every vertex towards the centroid of its neighbours within
// its tangent plane, and project it back onto the closest point of the input
// surface.
//
// mesh     input surface, must be convertible to a half-edge mesh without
//          dropping a face (edge-manifold, consistently oriented)
// options  see RemeshOptions
// Returns a new mesh whose vertices lie on the input surface. Closed manifold
// input gives closed manifold output of the same genus. Boundary vertices of
// open input never move and are never removed; boundary edges are only split.
// Creases are not kept as features: sharp edges are rounded at the scale of
// L. Input vertices used by no face are dropped.
// Throws InvalidInputError when target_edge_length is not a positive finite
// number, iterations < 1, the mesh has no face, an index or coordinate is
// invalid, a face had to be dropped while building the half-edge mesh, or the
// target is so small that the output would exceed 20 million faces.
IndexedMesh remesh_uniform(const IndexedMesh& mesh, const RemeshOptions& options);

}  // namespace mmm::mesh

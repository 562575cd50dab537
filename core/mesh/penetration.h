#pragma once
// Interpenetration of two surfaces, measured at the vertices of the first:
// which vertices of A lie inside B (generalized winding number of B > 1/2)
// and how deep (distance to B's surface). Used to check that scaled or
// registered bones and muscles do not overlap.

#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/signed_distance.h"

namespace mmm::mesh {

// vertices_inside  number of vertices of A inside B
// max_depth        largest distance from such a vertex to B's surface (mm); 0 if none
// deepest_vertex   row of A.V reaching max_depth; -1 if none
// inside_vertices  rows of A.V inside B, ascending
struct PenetrationReport {
  int vertices_inside = 0;
  double max_depth = 0;
  int deepest_vertex = -1;
  std::vector<int> inside_vertices;
};

// Vertices of `a` (V #V by 3, mm; faces are not used but must be valid) inside
// the surface behind `b`. Throws InvalidInputError on an invalid `a`.
PenetrationReport penetration(const IndexedMesh& a, const SignedDistance& b);

// Same, building the signed distance of `b` (closed, outward oriented) first.
// For many tests against the same b, build a SignedDistance once instead.
PenetrationReport penetration(const IndexedMesh& a, const IndexedMesh& b);

}  // namespace mmm::mesh

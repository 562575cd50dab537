#pragma once
// Mesh simplification by quadric-error edge collapses, for lower-resolution
// models (display, collision, fast distance queries).

#include <Eigen/Core>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

struct DecimateOptions {
  // Number of faces to reach. Must be >= 4 (a tetrahedron); a target at or
  // above the input's face count returns the input unchanged.
  Eigen::Index target_faces = 0;
  // A collapse is refused when it would turn the normal of any surviving face
  // around the removed vertex by more than this angle (degrees, in (0, 180]).
  // Small values keep creases and stop fold-overs; 180 only forbids flips.
  double max_normal_deviation_degrees = 60.0;
  // Keep every boundary vertex (open meshes): boundary vertices are never
  // removed, so the boundary polylines stay exactly as they are. With false,
  // boundary vertices may slide along the boundary onto a boundary neighbour.
  bool preserve_boundary = true;
};

struct DecimateReport {
  Eigen::Index faces_before = 0;
  Eigen::Index faces_after = 0;
};

// Greedy half-edge collapses ordered by the quadric error metric (Garland &
// Heckbert 1997) using OpenMesh's Decimater (ModQuadricT priority,
// ModNormalFlippingT for max_normal_deviation_degrees). Surviving vertices
// keep their input positions (a subset of the input vertices; no new points).
// Each collapse passes OpenMesh's topological link test, so a closed
// two-manifold stays closed, two-manifold and of the same genus.
//
// mesh     input, must be convertible to a half-edge mesh without dropping a
//          face (edge-manifold, no repeated index in a face)
// options  see DecimateOptions
// report   when given, receives the face counts before and after
// Returns the decimated mesh. faces_after can stay above target_faces when no
// legal collapse is left (a closed mesh near a tetrahedron, normal-deviation
// limit, locked boundary); it is never below target_faces - 1 (a collapse
// removes two faces inside, one on the boundary). Input vertices used by no
// face are dropped, so every output vertex is referenced.
// Throws InvalidInputError when target_faces < 4, the angle is outside
// (0, 180], an index or coordinate is invalid, or a face had to be dropped
// while building the half-edge mesh (non-manifold input: repair it first).
IndexedMesh decimate(const IndexedMesh& mesh, const DecimateOptions& options,
                     DecimateReport* report = nullptr);

}  // namespace mmm::mesh

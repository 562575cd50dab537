#pragma once
// Progressive outer hull: a coarse closed mesh that encloses the input, for
// conservative collision and wrapping tests against a few hundred faces
// instead of tens of thousands.

#include <Eigen/Core>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

struct ProgressiveHullOptions {
  // Number of faces to reach. Must be >= 4 (a tetrahedron); a target at or
  // above the input's face count returns the input unchanged.
  Eigen::Index target_faces = 1000;
  // A collapse is refused when it would turn the normal of any surviving face
  // around the collapsed edge by more than this angle (degrees, in (0, 180]).
  // 90 refuses flips and fold-overs; smaller values keep the hull's triangles
  // closer to the orientation of the faces they replace; 180 checks nothing.
  double max_normal_deviation_degrees = 90.0;
};

struct ProgressiveHullReport {
  Eigen::Index faces_before = 0;
  Eigen::Index faces_after = 0;
  double volume_before = 0;  // mm^3, enclosed by the input
  double volume_after = 0;   // mm^3, enclosed by the hull (>= volume_before)
  // Containment check of the input's vertices (those used by a face) against
  // the hull, by signed distance (SignedDistance): a vertex counts as outside
  // when it lies more than kProgressiveHullOnSurfaceTolerance (mm) outside
  // the hull. Both stay 0 unless rounding or a self-intersecting hull breaks
  // the guarantee.
  int vertices_outside = 0;
  double max_outside_mm = 0;  // largest signed distance of an input vertex, clamped at 0
};

// Distance (mm) outside the hull within which an input vertex still counts
// as on it: the hull's untouched vertices are input vertices, and the
// distance query rounds at ~1e-13 relative to coordinates of ~1000 mm.
inline constexpr double kProgressiveHullOnSurfaceTolerance = 1e-6;

// Greedy edge collapses that only ever move the surface outward (Sander, Gu,
// Gortler, Hoppe & Snyder 2000, "Silhouette clipping", progressive hulls).
// Each collapse places the merged vertex on or outside the plane of every
// face around the edge and, among such positions, where it adds the least
// volume (a 3-variable LP, solved exactly); the collapse adding the least
// volume goes first. By induction every hull contains the previous one, so
// the result encloses the input. A collapse is refused when it fails the link
// condition (OpenMesh's is_collapse_ok), turns a surviving face by more than
// max_normal_deviation_degrees, leaves a degenerate face, needs a vertex more
// than three neighbourhood radii from the edge, or gives the merged vertex
// more than 20 neighbours (keeps flat sides from fanning out of one vertex).
// O(n log n); ~0.25 s for 10K faces, ~0.6 s for 26K (Release).
//
// mesh     closed, two-manifold, outward-oriented triangle mesh without
//          degenerate faces (V #V by 3 in mm, F #F by 3); several closed
//          components are fine, each is hulled on its own
// options  see ProgressiveHullOptions
// report   when given, receives face counts, volumes and the containment
//          check (one signed-distance query per input vertex, ~10% extra time)
// Returns a closed, two-manifold, outward-oriented mesh of the input's genus
// whose vertices are all referenced. faces_after is target_faces or
// target_faces - 1 (a collapse removes two faces) unless no legal collapse is
// left first (only seen below ~25 faces: an icosphere goes down to a
// tetrahedron, the gluteus medius stops at 6 faces, a torus at 22). The hull is not checked for
// self-intersection: where two sheets of the input face each other across a narrow gap, a new
// vertex could pass through the opposite sheet (at 1000 faces: one crossing face pair on the VHF
// vastus intermedius, which wraps around the femur; none on the other 19 right-leg muscles). Throws
// InvalidInputError when target_faces < 4, the angle is outside (0, 180], an index or coordinate is
// invalid, or the mesh is open, non-manifold, inconsistently oriented, inward-facing or has
// degenerate faces (each message names the problem and a repair).
IndexedMesh progressive_hull(const IndexedMesh& mesh, const ProgressiveHullOptions& options,
                             ProgressiveHullReport* report = nullptr);

}  // namespace mmm::mesh

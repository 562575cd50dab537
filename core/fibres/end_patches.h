#pragma once
// A muscle's own ends: the patches of its surface where its fibres begin and
// end, found from the atlas's attachment areas on the bones.
//
// A segmented muscle surface lies on its bone only where the muscle attaches
// by flesh. Where it attaches by a tendon that the segmentation left out, the
// surface stops short of the bone (the Visible Human Female surfaces stop up
// to 340 mm short: the iliotibial tract of tensor fasciae latae), its fibres
// end on the muscle's end cap (the musculotendinous junction), and a tendon
// bridges the gap. One rule covers both, per attachment area:
//
//   d(v)   = distance from surface vertex v to the nearest point of the area
//   gap    = min over the vertices of d(v)     (0 where the muscle lies on it)
//   patch  = { v : d(v) <= gap + margin }
//
// A vertex within both patches goes to the one it exceeds by less
// (d(v) - gap); a patch left with fewer than 3 vertices takes the 3 with the
// least excess that the other does not hold. The patches are vertex indices,
// so they follow the surface through every frame of a wrapped muscle.

#include <Eigen/Core>
#include <vector>

#include "core/fibres/decomposition.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

struct EndPatches {
  std::vector<int> origin;     // surface vertices, ascending
  std::vector<int> insertion;  // disjoint from origin
  double origin_gap_mm = 0.0;  // closest approach of the origin area to the surface's vertices
  double insertion_gap_mm = 0.0;
};

constexpr double kEndPatchMarginMm = 3.0;

// Throws InvalidInputError when an area has no points, a point is not
// finite, the margin is negative or the surface has fewer than 6 vertices.
EndPatches end_patches(const mesh::IndexedMesh& surface, const Attachments& areas,
                       double margin_mm = kEndPatchMarginMm);

// The patches' vertices at `positions` (the surface's vertices, moved) as
// the attachments the decomposition methods take; the area sizes (which end
// is narrow) are those of `areas`.
Attachments patch_attachments(const EndPatches& patches, const Eigen::MatrixX3d& positions,
                              const Attachments& areas);

// The closest approach (mm) of `points` to the vertices `patch` at
// `positions`: the length a tendon from the muscle's end to its area at
// least has (0 where the muscle lies on the bone).
double patch_gap(const std::vector<int>& patch, const Eigen::MatrixX3d& positions,
                 const Eigen::MatrixX3d& points);

}  // namespace mmm::fibres

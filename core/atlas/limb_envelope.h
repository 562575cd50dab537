#pragma once
// The body's outline around bones and muscles, for radiographs of synthetic
// patients in which soft tissue fills the limb (as in a real one) rather than
// muscles standing in air.
//
// Lofted from slices: along z every slice_mm, the points of the given
// surfaces within the slab (the slab widened by half a slice each side), their
// 2D convex hull in (x, y), resampled as a star polygon of `sectors` radii
// around its centroid and pushed outward by `fat_mm` (skin and subcutaneous
// fat); the rings smoothed along z (weights 1 2 3 2 1, never closer than
// half the fat to their slice's hull), consecutive rings joined into a tube,
// each run of non-empty slices one closed component (fan caps at its ends),
// faces outward.

#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::atlas {

struct LimbEnvelopeOptions {
  double slice_mm = 5.0;
  int sectors = 48;
  double fat_mm = 8.0;
};

// Throws InvalidInputError for no surface, a slice <= 0, fewer than 8 sectors
// or a negative fat thickness.
mesh::IndexedMesh limb_envelope(const std::vector<const mesh::IndexedMesh*>& surfaces,
                                const LimbEnvelopeOptions& options = {});

}  // namespace mmm::atlas

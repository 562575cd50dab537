#pragma once
// Rest-pose clean-up of a muscle surface that enters bones: segmented
// surfaces of different origins (the Visible Human muscles, a registered
// OpenSim femur) overlap by a few millimetres where they touch. Every
// muscle vertex deeper than `tolerance_mm` inside a bone is moved to the
// bone surface (plus `margin_mm` outside it); the vertices around the moved
// ones are then relaxed (umbrella smoothing of the 2-ring, the moved
// vertices held) so that no spike is left; repeated until no vertex is
// deeper than the tolerance or `max_rounds` is reached.

#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/signed_distance.h"

namespace mmm::atlas {

struct MuscleCleanupOptions {
  double tolerance_mm = 0.5;  // deepest allowed vertex inside a bone
  double margin_mm = 0.2;     // a moved vertex ends this far outside the bone
  int smoothing_iterations = 3;
  int max_rounds = 6;
};

struct MuscleCleanupReport {
  double max_depth_before_mm = 0.0;
  double max_depth_after_mm = 0.0;
  int vertices_moved = 0;  // distinct vertices moved at least once
  double volume_before_mm3 = 0.0;
  double volume_after_mm3 = 0.0;
};

// `bones`: signed distances of the bone surfaces (closed, outward). The
// muscle keeps its connectivity; only positions change.
MuscleCleanupReport push_muscle_out_of_bones(mesh::IndexedMesh& muscle,
                                             const std::vector<const mesh::SignedDistance*>& bones,
                                             const MuscleCleanupOptions& options = {});

}  // namespace mmm::atlas

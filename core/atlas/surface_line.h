#pragma once
// The action line of a muscle that the OpenSim model has no path for
// (plantaris, popliteus, the obturators in gait2392): from the middle of the
// muscle's contact with its origin bone to the middle of its contact with its
// insertion bone, each end on the bone's surface. The atlas builder then keeps
// it inside the muscle like any other line (action_line_fit.h).

#include <string>

#include "core/atlas/atlas.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

struct SurfaceLineBone {
  std::string name;
  const mesh::AabbTree* surface = nullptr;
};

struct SurfaceLine {
  ActionLine line;
  // The path from where it first enters the muscle to where it last leaves
  // it (the belly: fibre length for the model) and the rest of the path's
  // length (tendon), mm.
  double belly_mm = 0.0;
  double tendon_mm = 0.0;
};

// The muscle vertices within `contact_mm` of a bone make its contact (when
// fewer than 8 do, the 2 % nearest, at least 8: a muscle held by a tendon
// the segmentation left out); their centroid, moved onto the bone, is an end.
// Between the ends, via points at the centroids of slices of the belly across
// the line (one every ~10 mm, 3 to 12) keep it in the muscle; each rides on the nearer end's bone.
SurfaceLine surface_action_line(const std::string& name, const mesh::IndexedMesh& muscle,
                                const SurfaceLineBone& origin, const SurfaceLineBone& insertion,
                                double contact_mm);

}  // namespace mmm::atlas

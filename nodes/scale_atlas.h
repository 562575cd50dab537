#pragma once
// Node `scale_atlas`: the generic atlas morphed onto the patient's landmarks
// (core/scaling/atlas_scaling.h): every bone, muscle, level of detail,
// landmark, marker, joint, action-line point, attachment area and wrap
// obstacle, consistently.
//
//   input  atlas        Atlas         the generic atlas
//   input  landmarks    LandmarkSet   femoral-head and patella centres required,
//                                     ankle centre and further atlas landmarks optional
//   input  radiographs  RadiographPair  optional: for the overlay picture
//   output atlas        Atlas         the patient's atlas (in the landmarks' frame)
//   output report       Report        per-landmark residuals, per-segment factors,
//                                     per-muscle volume and penetration, timings
//   output overlay      File          PNG: the scaled bones' projected outlines on
//                                     both radiographs (without radiographs: the
//                                     scaled bones from the front and the side)
//
// Parameters: the energy's weights and the non-penetration settings, with the
// defaults of AtlasScalingOptions (documented there and in `mmm nodes`).

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct ScaleAtlas {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

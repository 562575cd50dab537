#pragma once
// Node `fit_bone_outlines`: the scaled atlas's bones fitted to their outlines
// on the patient's radiograph pair (core/outlines/atlas_outline_fit.h), and
// everything that follows the bones (muscles, cartilages, landmarks, joints,
// action lines, attachment areas) carried with them as in the scaling
// (core/scaling/atlas_scaling.h, carry_atlas).
//
//   input  atlas        Atlas           the scaled atlas (scale_atlas)
//   input  radiographs  RadiographPair  the patient's calibrated pair
//   input  landmarks    LandmarkSet     optional: the operator's landmarks, held
//   input  corrections  OutlineCorrections  optional: an operator's review of the
//                                       atlas's outlines (outline_review): "accept"
//                                       passes the atlas through unchanged;
//                                       "correct" fits again with the operator's
//                                       points as strong terms (a corrected bone
//                                       is fitted even when not in `bones`)
//   output atlas        Atlas           the patient's atlas, bones fitted
//   output report       Report          per bone and view: contour residual
//                                       before/after (mm), matched share, how
//                                       far the surface moved, the share held
//                                       by the prior, convergence; timings
//   output overlay      File            PNG: the scaled outline (red) and the
//                                       fitted one (green) on both radiographs

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct FitBoneOutlines {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

#pragma once
// Node `simulate_muscles`: muscle wrapping over a fused motion, volumetric
// pathway (core/volumetric/muscle_simulation.h). Every muscle in one
// conforming tetrahedral model whose touching muscles share their interface,
// moved by the bones: per frame one quasi-static simulation step with each
// muscle's volume restored exactly, its attachments following their bones and
// its surface kept out of them. Same outputs as wrap_muscles.
//
//   input  atlas      Atlas      the (scaled) atlas the motion drives
//   input  motion     BonePoses  from fuse_motion on this atlas
//   input  lattice    File       optional: build_muscle_lattice's model at rest
//                                (else it is built here from spacing_mm)
//   output animation  File       folder bundle: wrapping.pvd + per-frame .vtp
//   output metrics    File       CSV per muscle and frame (as wrap_muscles)
//   output lines      File       CSV per action line and frame: length, moment arms
//   output plot       File       SVG: volume error, penetration, time per frame
//   output report     Report     per-muscle summaries, the model, timings, targets

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct SimulateMuscles {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

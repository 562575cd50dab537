#pragma once
// Node `wrap_muscles`: muscle wrapping over a fused motion, energy-
// minimisation pathway (core/wrapping/muscle_wrapping.h): per frame, action
// lines re-routed on the moving skeleton, each muscle surface deformed around
// them with its volume held exactly and contacts keeping it out of the bones,
// coarse to fine (the muscle's progressive hull first, then its surface).
//
//   input  atlas      Atlas      the (scaled) atlas the motion drives
//   input  motion     BonePoses  from fuse_motion on this atlas
//   input  hulls      File       optional: build_hulls's stored hulls (coarse to fine); a
//                                muscle whose surface changed gets a new hull here
//   output animation  File       folder bundle: wrapping.pvd + per-frame .vtp of every
//                                muscle, the bones and the action lines, for ParaView
//   output metrics    File       CSV, one row per muscle and frame: volume error, bone
//                                penetration (depth, vertices), contacts, smoothness, time
//   output lines      File       CSV, one row per action line and frame: length and moment
//                                arms about the hip and knee coordinates
//   output plot       File       SVG: volume error, penetration depth and time per frame
//   output report     Report     per-muscle summaries, targets met or not, timings

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct WrapMuscles {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

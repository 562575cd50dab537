#pragma once
// Node `fuse_motion`: a marker trial drives a model frame by frame
// (core/motion/: Kabsch per body, Ceres chain fit, Kalman filter and RTS
// smoother, joint limits), optionally retargeted to a patient.
//
//   input  trial         File        marker trial (.trc); gaps and NaN frames allowed
//   input  atlas         Atlas       optional: the patient's (scaled) atlas to drive
//   input  model         File        optional: an OpenSim model (.osim). Alone: driven
//                                    itself. With an atlas: the trial subject's model; the
//                                    motion is fitted to it and retargeted to the atlas
//   input  mapping       File        optional: marker mapping (YAML); default: gait2392's
//   input  static_trial  File        optional: standing trial (.trc): markers of the fitted
//                                    model are first placed where the subject wore them
//   input  reference     File        optional: joint angles to compare with (.mot)
//   output motion        BonePoses   per-frame coordinates, body poses, marker errors
//   output angles        File        .mot of the joint angles (deg, m; OpenSim opens it)
//   output points        File        CSV: every landmark, attachment area, action-line
//                                    point and marker per frame (an OpenSim model: markers)
//   output report        Report      markers used/skipped, residuals, filter, retargeting,
//                                    comparison with the reference, timings
//   output plot          File        SVG: joint angles over time (beside the reference)
//   output animation     File        folder bundle: <name>.pvd + per-frame .vtp (bones of
//                                    an atlas, a stick figure, action lines) for ParaView

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct FuseMotion {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

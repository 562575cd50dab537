#pragma once
// Node `static_trial_landmarks`: joint-centre landmarks from a static
// motion-capture trial, for studies with motion capture but no radiographs
// (core/landmarks/static_trial_landmarks.h): knee and ankle centres as
// midpoints of the medial and lateral markers, hip centres by the Harrington
// et al. 2007 regression, averaged over the trial's frames.
//
//   input  trial      File         the static trial (.trc; gait2392 marker names)
//   param  legs       enum         right | left | both (default both)
//   output landmarks  LandmarkSet  lab frame (the trial's axes), mm

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct StaticTrialLandmarks {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

#include "nodes/static_trial_landmarks.h"

#include "core/landmarks/landmark_set.h"
#include "core/landmarks/static_trial_landmarks.h"
#include "core/opensim/trc.h"

namespace mmm::nodes {

workflow::NodeSpec StaticTrialLandmarks::spec() {
  using workflow::port::File;
  using workflow::port::LandmarkSet;
  return workflow::NodeSpec{"static_trial_landmarks", 1,
                            "Hip, knee and ankle centres from a static marker trial (Harrington "
                            "hip regression, medial/lateral marker midpoints)"}
      .input<File>("trial", "Static trial (.trc) with the gait2392 marker set")
      .param_enum("legs", "both", {"right", "left", "both"}, "The legs to compute")
      .output<LandmarkSet>("landmarks", "Joint centres, lab frame (mm)");
}

void StaticTrialLandmarks::run(workflow::NodeContext& context) {
  const opensim::MarkerTrajectories trial =
      opensim::parse_trc(context.input_bytes("trial"), context.input("trial").path);
  landmarks::StaticTrialOptions options;
  options.legs = context.text("legs");
  const landmarks::StaticTrialResult result =
      landmarks::landmarks_from_static_trial(trial, options);
  context.info("pelvis width " + std::to_string(result.pelvis_width_mm) + " mm, depth " +
               std::to_string(result.pelvis_depth_mm) + " mm");
  for (const landmarks::StaticTrialLandmarkInfo& info : result.info) {
    context.info(info.name + ": " + std::to_string(info.frames_used) + " frames, spread " +
                 std::to_string(info.spread_mm) + " mm");
  }
  context.set_output("landmarks", landmarks::landmark_set_to_json_text(result.landmarks));
}

}  // namespace mmm::nodes

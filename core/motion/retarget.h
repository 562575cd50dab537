#pragma once
// Motion retargeting: a motion fused on the trial subject's model drives a
// different patient. Joint angles transfer by coordinate name (they mean the
// same on both: the atlas keeps OpenSim's joint definitions); the root's
// translations scale with the ratio of leg lengths (hip to knee to ankle
// centres): its height in full, its horizontal travel from where the
// subject started, so the patient walks with the subject's stride in
// proportion to its own size; then the patient is shifted vertically so
// that its lowest foot marker touches the ground as low as the subject's
// did, on the same foot (ground contact kept). The result is measured, not assumed: the
// patient's markers against the trial's, and the foot heights of both, for
// a person to judge.
//
// World: the trial's lab frame, y up (OpenSim's convention).

#include <string>
#include <vector>

#include "core/motion/marker_mapping.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/skeleton.h"
#include "core/opensim/trc.h"

namespace mmm::motion {

struct RetargetOptions {
  bool keep_ground_contact = true;
};

struct Retargeted {
  FusedMotion motion;             // of the target skeleton; marker errors against the trial
  double leg_length_ratio = 1.0;  // target / source
  double vertical_shift_mm = 0.0;
  std::vector<std::string> transferred;  // coordinates copied (scaled for lengths)
  std::vector<std::string> defaulted;    // target coordinates the source lacks: at default
  // Lowest foot marker height (y, mm) over the frames: min and max, of the
  // source model and of the target after retargeting; NaN without foot markers.
  double source_foot_min_mm = 0.0;
  double source_foot_max_mm = 0.0;
  double target_foot_min_mm = 0.0;
  double target_foot_max_mm = 0.0;
  // RMS of the patient's markers against the trial's after removing each
  // frame's mean offset (mm): the difference in body configuration.
  double aligned_marker_rms_mm = 0.0;
  std::vector<std::string> notes;
};

// Throws InvalidInputError when the target has no coordinate in common
// with the source (nothing would move it), or from bind_tracking.
Retargeted retarget_motion(const FusedMotion& source, const Skeleton& source_skeleton,
                           const Skeleton& target, const opensim::MarkerTrajectories& trial,
                           const MarkerMapping& mapping, const RetargetOptions& options = {});

// Hip-knee plus knee-ankle distance at the default pose (mm), from the
// joints moved by hip_flexion_<side>, knee_angle_<side>, ankle_angle_<side>
// (right side first); nullopt when the skeleton lacks them.
std::optional<double> leg_length_mm(const Skeleton& skeleton);

}  // namespace mmm::motion

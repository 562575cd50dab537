#pragma once
// Marker placement from a static trial (what OpenSim's Scale tool does after
// scaling): the subject stands still, the model is posed by inverse
// kinematics on the trial's mean marker positions, and every marker that is
// not `fixed` is moved, on its body, to where it was measured. Skin markers
// are never where a generic model puts them; moving them once removes a
// constant offset from every frame of the motion trials (hip rotation in
// particular depends on where the thigh markers really are).

#include <string>
#include <vector>

#include "core/motion/marker_mapping.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/skeleton.h"
#include "core/opensim/trc.h"

namespace mmm::motion {

struct MarkerPlacementOptions {
  MotionFusionOptions fusion;  // start/end select the standing frames (default: all)
  bool move_fixed = false;     // also move markers marked fixed
  // A marker that would move farther than this is left in place and
  // reported (a swapped or mislabelled marker, not a placement error).
  double max_move_mm = 150.0;
};

struct PlacedMarker {
  std::string name;
  double moved_mm = 0.0;
  bool moved = false;
};

struct MarkerPlacement {
  Skeleton skeleton;                  // the input with its markers moved
  Eigen::VectorXd static_pose;        // coordinates of the standing pose (rad, mm)
  double rms_before_mm = 0.0;         // tracked markers at the standing pose, before moving
  double rms_after_mm = 0.0;          // and after
  std::vector<PlacedMarker> markers;  // every tracked marker
  int frames_averaged = 0;
  std::vector<std::string> notes;
};

// Throws like fuse_motion, and InvalidInputError when no tracked marker is
// present in any selected frame of the static trial.
MarkerPlacement place_markers(const Skeleton& skeleton,
                              const opensim::MarkerTrajectories& static_trial,
                              const MarkerMapping& mapping,
                              const MarkerPlacementOptions& options = {});

}  // namespace mmm::motion

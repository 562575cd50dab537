#pragma once
// Joint-centre landmarks from a static motion-capture trial (.trc,
// core/opensim/trc.h), for studies without radiographs.
//
//   knee centre  = midpoint of the lateral and medial knee (epicondyle) markers
//   ankle centre = midpoint of the lateral and medial malleolus markers
//   hip centre   = Harrington et al. regression in the pelvis frame:
//     origin O = midpoint of the ASISs
//     z = unit(RASIS - LASIS)                        (toward the right)
//     x = unit(O - P projected normal to z)          (anterior; P = PSIS midpoint
//                                                     or the sacral marker)
//     y = z cross x                                  (superior)
//     PW = |RASIS - LASIS|, PD = |O - P|             (pelvis width and depth, mm)
//     hip = O + (-0.24 PD - 9.9) x + (-0.30 PW - 10.9) y + s (0.33 PW + 7.3) z
//     with s = +1 right, -1 left. Harrington, Zavatsky, Lawson, Yuan &
//     Theologis 2007, "Prediction of the hip joint centre in adults, children,
//     and patients with cerebral palsy based on magnetic resonance imaging",
//     J Biomech 40:595-602: their regression on PW and PD only (the one
//     adding leg length is not used), fitted to MRI-measured hip centres, in
//     the ISB pelvis frame above (x anterior, y superior, z right).
// Each landmark is computed in every frame where all its markers are present
// (NaN gaps skipped) and the frames are averaged.
//
// Output frame "lab": the trial's own axes and origin, in mm (the file's units
// converted). The landmarks keep the anatomy-agnostic lab axes; aligning them
// with the patient frame is the job of the node that uses them.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/landmarks/landmark_set.h"
#include "core/opensim/trc.h"

namespace mmm::landmarks {

// Marker names, defaults of the gait2392 marker set of
// gait2392/Pipelines/subject01_static.trc.
struct StaticTrialMarkers {
  std::string asis_r = "R.ASIS";
  std::string asis_l = "L.ASIS";
  // The posterior pelvis: one sacral marker, or the two PSIS markers (their
  // midpoint is used). Exactly one or two names.
  std::vector<std::string> posterior = {"V.Sacral"};
  std::string knee_lateral_r = "R.Knee.Lat";
  std::string knee_medial_r = "R.Knee.Med";
  std::string knee_lateral_l = "L.Knee.Lat";
  std::string knee_medial_l = "L.Knee.Med";
  std::string ankle_lateral_r = "R.Ankle.Lat";
  std::string ankle_medial_r = "R.Ankle.Med";
  std::string ankle_lateral_l = "L.Ankle.Lat";
  std::string ankle_medial_l = "L.Ankle.Med";
};

struct StaticTrialOptions {
  StaticTrialMarkers markers;
  // Legs to compute: "right", "left" or "both".
  std::string legs = "both";
  // Fewest frames with all of a landmark's markers present (>= 1). 10 frames
  // (1/6 s at 60 Hz) average out marker jitter; a static trial has hundreds.
  int min_valid_frames = 10;
};

// Hip centres of one frame by the Harrington regression (see the file
// comment). Positions in mm, any frame; the result is in the same frame.
struct HarringtonHipCentres {
  Eigen::Vector3d right = Eigen::Vector3d::Zero();  // mm
  Eigen::Vector3d left = Eigen::Vector3d::Zero();   // mm
  double pelvis_width_mm = 0;                       // PW
  double pelvis_depth_mm = 0;                       // PD
};

// Throws InvalidInputError for a non-finite position, coincident ASISs, or a
// posterior point on the inter-ASIS line (no pelvis frame).
HarringtonHipCentres harrington_hip_centres(const Eigen::Vector3d& asis_r,
                                            const Eigen::Vector3d& asis_l,
                                            const Eigen::Vector3d& posterior);

// How one landmark was obtained.
struct StaticTrialLandmarkInfo {
  std::string name;
  int frames_used = 0;  // frames with all its markers present
  // RMS distance of the per-frame positions from their mean (mm): how still
  // the subject stood and how steady the markers were.
  double spread_mm = 0;
};

struct StaticTrialResult {
  // frame "lab", source "static_trial"; names femoral_head_centre_{r,l},
  // knee_centre_{r,l}, ankle_centre_{r,l}, asis_r, asis_l (mm).
  LandmarkSet landmarks;
  std::vector<StaticTrialLandmarkInfo> info;  // same order as landmarks
  double pelvis_width_mm = 0;                 // mean over the pelvis frames
  double pelvis_depth_mm = 0;
};

// Throws InvalidInputError naming the trial file when a mapped marker is not
// in the trial (with a did-you-mean over its marker names), a landmark has
// fewer than min_valid_frames complete frames, or the options are invalid.
StaticTrialResult landmarks_from_static_trial(const opensim::MarkerTrajectories& trial,
                                              const StaticTrialOptions& options = {});

}  // namespace mmm::landmarks

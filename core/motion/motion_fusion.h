#pragma once
// Motion fusion (reference method, section 3.3): a marker trial drives the
// skeleton frame by frame.
//
//   for each frame f in [start, end]:
//     each body with >= 3 tracked markers present: weighted rigid
//       registration (Kabsch/Umeyama, core/fit/rigid_fit.h) of its model
//       markers onto the measured ones -> free-body pose, cluster residual
//     first frame: root coordinates from the root's free-body pose
//       (multi-start Gauss-Newton on its joint), the rest at defaults
//     prior = filter.predict(dt)          (Kalman-like, motion_filter.h)
//     q_f   = chain fit (chain_fit.h), warm-started from the prior's mean
//     filter.update(q_f)
//   smoother (optional): Rauch-Tung-Striebel over the whole trial
//   poses, marker errors at the final q
//
// The free-body poses are reported beside the chain's (cluster residual per
// body, joint dislocation per joint) to show what the kinematic chain
// corrects: skin-marker clusters are not rigid, free bodies drift apart.

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "core/motion/chain_fit.h"
#include "core/motion/marker_mapping.h"
#include "core/motion/motion_filter.h"
#include "core/motion/skeleton.h"
#include "core/opensim/trc.h"

namespace mmm::motion {

struct MotionFusionOptions {
  ChainFitOptions fit;
  MotionFilterOptions filter;
  std::optional<double> start_time;  // s; default: the trial's first frame
  std::optional<double> end_time;    // s; default: its last frame
};

// Per body: how rigid its marker cluster is and how far the free-body
// registrations would pull the joint apart (medians over the frames).
struct BodyRegistrationSummary {
  std::string body;
  int frames_registered = 0;    // frames with >= 3 of its markers present
  double cluster_rms_mm = 0.0;  // median of the Kabsch RMS residual
  double joint_gap_mm = 0.0;    // median distance between the joint centre as the free
                                // parent and the free child place it (NaN: no parent pair)
};

struct FusedMotion {
  std::vector<std::string> coordinate_names;
  std::vector<CoordinateUnit> coordinate_units;
  std::vector<std::string> body_names;
  std::vector<std::string> marker_names;              // tracked model markers, as columns below
  Eigen::VectorXd times;                              // #frames (s)
  std::vector<int> trial_frames;                      // #frames, 0-based rows of the trial
  Eigen::MatrixXd coordinates;                        // #frames by #coordinates (rad, mm)
  std::vector<std::vector<Eigen::Isometry3d>> poses;  // [frame][body], body -> world (mm)
  Eigen::MatrixXd marker_errors;                      // #frames by #markers (mm); NaN where missing
  Eigen::VectorXd rms_mm;                             // #frames, over the markers present
  Eigen::VectorXd max_mm;
  Eigen::VectorXi markers_used;
  Eigen::VectorXi iterations;   // chain-fit iterations per frame
  Eigen::VectorXd fit_seconds;  // chain-fit wall time per frame (s)
  std::vector<BodyRegistrationSummary> registrations;
  TrackingSetup setup;
  FilterMode filter = FilterMode::kNone;
  std::vector<std::string> notes;  // frames without markers, unconverged fits, ...

  [[nodiscard]] Eigen::Index num_frames() const { return times.size(); }
  // Column of a coordinate, or nullopt.
  [[nodiscard]] std::optional<int> coordinate_index(std::string_view name) const;
  // RMS of all marker errors present over all frames (mm).
  [[nodiscard]] double overall_rms_mm() const;
};

// Throws InvalidInputError (trial file named) when no frame lies in
// [start_time, end_time] or no frame has 3 of the root's tracked markers
// (nothing can place it), and from bind_tracking; SolverError when a fit
// fails.
FusedMotion fuse_motion(const Skeleton& skeleton, const opensim::MarkerTrajectories& trial,
                        const MarkerMapping& mapping, const MotionFusionOptions& options = {});

// Body poses of a coordinate table: [frame][body].
std::vector<std::vector<Eigen::Isometry3d>> poses_of(const Skeleton& skeleton,
                                                     const Eigen::MatrixXd& coordinates);

}  // namespace mmm::motion

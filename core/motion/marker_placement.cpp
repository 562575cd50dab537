#include "core/motion/marker_placement.h"

#include <cmath>

#include "core/errors.h"

namespace mmm::motion {
namespace {

// One frame: the mean of every marker over the selected frames where it is
// present (NaN when never present).
opensim::MarkerTrajectories mean_frame(const opensim::MarkerTrajectories& trial,
                                       const MotionFusionOptions& options, int& frames_used) {
  const double slack = trial.data_rate > 0 ? 0.5 / trial.data_rate : 1e-9;
  const double start = options.start_time.value_or(-1e300) - slack;
  const double end = options.end_time.value_or(1e300) + slack;
  opensim::MarkerTrajectories mean = trial;
  mean.frame_numbers = {1};
  mean.times = Eigen::VectorXd::Zero(1);
  mean.positions = Eigen::MatrixXd::Constant(1, trial.positions.cols(), std::nan(""));
  frames_used = 0;
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(trial.positions.cols());
  Eigen::VectorXd counts = Eigen::VectorXd::Zero(trial.positions.cols());
  for (Eigen::Index f = 0; f < trial.num_frames(); ++f) {
    if (trial.times(f) < start || trial.times(f) > end) continue;
    ++frames_used;
    for (Eigen::Index c = 0; c < trial.positions.cols(); ++c) {
      if (std::isfinite(trial.positions(f, c))) {
        sums(c) += trial.positions(f, c);
        counts(c) += 1;
      }
    }
  }
  for (Eigen::Index c = 0; c < trial.positions.cols(); ++c) {
    if (counts(c) > 0) mean.positions(0, c) = sums(c) / counts(c);
  }
  return mean;
}

}  // namespace

MarkerPlacement place_markers(const Skeleton& skeleton,
                              const opensim::MarkerTrajectories& static_trial,
                              const MarkerMapping& mapping, const MarkerPlacementOptions& options) {
  MarkerPlacement placement;
  placement.skeleton = skeleton;
  const opensim::MarkerTrajectories mean =
      mean_frame(static_trial, options.fusion, placement.frames_averaged);
  if (placement.frames_averaged == 0) {
    throw InvalidInputError(static_trial.source.string() +
                            ": no frame of the static trial lies in the selected time range");
  }
  MotionFusionOptions fusion = options.fusion;
  fusion.start_time.reset();
  fusion.end_time.reset();
  fusion.filter.mode = FilterMode::kNone;
  const FusedMotion standing = fuse_motion(skeleton, mean, mapping, fusion);
  if (standing.markers_used(0) == 0) {
    throw InvalidInputError(static_trial.source.string() +
                            ": no tracked marker is present in the static trial");
  }
  placement.static_pose = standing.coordinates.row(0).transpose();
  placement.rms_before_mm = standing.rms_mm(0);
  const std::vector<Eigen::Isometry3d>& poses = standing.poses.front();
  double squares = 0.0;
  int present = 0;
  for (std::size_t i = 0; i < standing.setup.markers.size(); ++i) {
    const BoundMarker& bound = standing.setup.markers[i];
    SkeletonMarker& marker = placement.skeleton.markers[static_cast<std::size_t>(bound.model)];
    PlacedMarker placed{marker.name, 0.0, false};
    const double error = standing.marker_errors(0, static_cast<Eigen::Index>(i));
    if (!std::isfinite(error)) {
      placement.notes.push_back(marker.name + ": not in the static trial, left in place");
      placement.markers.push_back(placed);
      continue;
    }
    double left = error;
    if (!marker.fixed || options.move_fixed) {
      if (error <= options.max_move_mm) {
        const Eigen::Vector3d measured = mean.unit_to_mm * mean.position(0, bound.trial);
        marker.local = poses[static_cast<std::size_t>(marker.body)].inverse() * measured;
        placed.moved_mm = error;
        placed.moved = true;
        left = 0.0;
      } else {
        placement.notes.push_back(marker.name + ": " + std::to_string(error) +
                                  " mm from the model's, beyond max_move_mm; left in place "
                                  "(mislabelled marker?)");
      }
    }
    squares += left * left;
    ++present;
    placement.markers.push_back(placed);
  }
  placement.rms_after_mm = present > 0 ? std::sqrt(squares / present) : 0.0;
  return placement;
}

}  // namespace mmm::motion

#include "core/motion/retarget.h"

#include <cmath>
#include <limits>

#include "core/errors.h"

namespace mmm::motion {
namespace {

// The body whose own joint uses `coordinate`.
std::optional<int> body_driven_by(const Skeleton& skeleton, const std::string& coordinate) {
  const std::optional<int> index = skeleton.coordinate_index(coordinate);
  if (!index) return std::nullopt;
  for (std::size_t b = 0; b < skeleton.bodies.size(); ++b) {
    for (const SkeletonAxis& axis : skeleton.bodies[b].axes) {
      if (axis.coordinate == *index) return static_cast<int>(b);
    }
  }
  return std::nullopt;
}

bool is_foot(const std::string& body) {
  return body.starts_with("calcn") || body.starts_with("toes") || body.starts_with("foot");
}

// Per frame, the lowest (y) marker on a foot body that `other` also has
// (so that a two-legged subject is compared with a one-legged patient on the
// same foot); NaN without one.
Eigen::VectorXd lowest_foot_marker(const Skeleton& skeleton, const Eigen::MatrixXd& coordinates,
                                   const Skeleton& other) {
  Eigen::VectorXd lowest = Eigen::VectorXd::Constant(coordinates.rows(), std::nan(""));
  SkeletonPose pose(skeleton);
  for (Eigen::Index k = 0; k < coordinates.rows(); ++k) {
    pose.set(coordinates.row(k).transpose());
    double low = std::numeric_limits<double>::infinity();
    for (std::size_t m = 0; m < skeleton.markers.size(); ++m) {
      const SkeletonMarker& marker = skeleton.markers[m];
      const std::string& body = skeleton.bodies[static_cast<std::size_t>(marker.body)].name;
      if (!is_foot(body) || !other.body_index(body)) continue;
      low = std::min(low, pose.marker(static_cast<int>(m)).y());
    }
    if (std::isfinite(low)) lowest(k) = low;
  }
  return lowest;
}

// The root's coordinate translating along world y (parent frame = world).
std::optional<int> vertical_root_coordinate(const Skeleton& skeleton) {
  if (skeleton.bodies.empty()) return std::nullopt;
  const SkeletonBody& root = skeleton.bodies.front();
  for (const SkeletonAxis& axis : root.axes) {
    if (axis.rotation || axis.coordinate < 0) continue;
    const Eigen::Vector3d direction = root.parent_offset.linear() * axis.direction;
    if (direction.y() > 0.999) return axis.coordinate;
  }
  return std::nullopt;
}

}  // namespace

std::optional<double> leg_length_mm(const Skeleton& skeleton) {
  SkeletonPose pose(skeleton);
  pose.set(skeleton.default_coordinates());
  for (const char* side : {"_r", "_l"}) {
    const auto hip = body_driven_by(skeleton, std::string("hip_flexion") + side);
    const auto knee = body_driven_by(skeleton, std::string("knee_angle") + side);
    const auto ankle = body_driven_by(skeleton, std::string("ankle_angle") + side);
    if (!hip || !knee || !ankle) continue;
    const auto centre = [&](int body) {
      return pose.point(body,
                        skeleton.bodies[static_cast<std::size_t>(body)].child_offset.translation());
    };
    return (centre(*hip) - centre(*knee)).norm() + (centre(*knee) - centre(*ankle)).norm();
  }
  return std::nullopt;
}

Retargeted retarget_motion(const FusedMotion& source, const Skeleton& source_skeleton,
                           const Skeleton& target, const opensim::MarkerTrajectories& trial,
                           const MarkerMapping& mapping, const RetargetOptions& options) {
  Retargeted result;
  const std::optional<double> source_leg = leg_length_mm(source_skeleton);
  const std::optional<double> target_leg = leg_length_mm(target);
  if (source_leg && target_leg && *source_leg > 0) {
    result.leg_length_ratio = *target_leg / *source_leg;
  } else {
    result.notes.emplace_back(
        "leg lengths not measurable on both models (hip_flexion/knee_angle/ankle_angle joints); "
        "root translations copied unscaled");
  }
  const Eigen::Index frames = source.num_frames();
  const std::optional<int> vertical = vertical_root_coordinate(target);
  Eigen::MatrixXd coordinates(frames, target.num_coordinates());
  for (int c = 0; c < target.num_coordinates(); ++c) {
    const SkeletonCoordinate& coordinate = target.coordinates[static_cast<std::size_t>(c)];
    const std::optional<int> from = source.coordinate_index(coordinate.name);
    if (!from) {
      coordinates.col(c).setConstant(coordinate.default_value);
      result.defaulted.push_back(coordinate.name);
      continue;
    }
    coordinates.col(c) = source.coordinates.col(*from);
    if (coordinate.unit == CoordinateUnit::kLength) {
      // Height in proportion to the legs; horizontal travel in proportion
      // to the stride, from where the subject started.
      const double start = c == vertical.value_or(-1) ? 0.0 : source.coordinates(0, *from);
      coordinates.col(c).array() =
          start + result.leg_length_ratio * (coordinates.col(c).array() - start);
    }
    if (coordinate.clamped && coordinate.lower < coordinate.upper && !coordinate.locked) {
      coordinates.col(c) = coordinates.col(c).cwiseMax(coordinate.lower).cwiseMin(coordinate.upper);
    }
    result.transferred.push_back(coordinate.name);
  }
  if (result.transferred.empty()) {
    throw InvalidInputError("retargeting: the patient's model '" + target.name +
                            "' shares no coordinate name with the subject's '" +
                            source_skeleton.name + "'; nothing would move it");
  }

  const Eigen::VectorXd source_feet =
      lowest_foot_marker(source_skeleton, source.coordinates, target);
  result.source_foot_min_mm = source_feet.minCoeff();
  result.source_foot_max_mm = source_feet.maxCoeff();
  Eigen::VectorXd target_feet = lowest_foot_marker(target, coordinates, source_skeleton);
  if (options.keep_ground_contact && vertical && std::isfinite(target_feet.minCoeff()) &&
      std::isfinite(source_feet.minCoeff())) {
    result.vertical_shift_mm = source_feet.minCoeff() - target_feet.minCoeff();
    coordinates.col(*vertical).array() += result.vertical_shift_mm;
    target_feet.array() += result.vertical_shift_mm;
  } else if (options.keep_ground_contact) {
    result.notes.emplace_back(
        "ground contact not adjusted: no foot markers or no vertical root "
        "translation on one of the models");
  }
  result.target_foot_min_mm = target_feet.minCoeff();
  result.target_foot_max_mm = target_feet.maxCoeff();

  FusedMotion& motion = result.motion;
  motion.setup = bind_tracking(target, mapping, trial.marker_names);
  for (const SkeletonCoordinate& c : target.coordinates) {
    motion.coordinate_names.push_back(c.name);
    motion.coordinate_units.push_back(c.unit);
  }
  for (const SkeletonBody& b : target.bodies) motion.body_names.push_back(b.name);
  for (const BoundMarker& m : motion.setup.markers) motion.marker_names.push_back(m.name);
  motion.times = source.times;
  motion.trial_frames = source.trial_frames;
  motion.coordinates = coordinates;
  motion.poses = poses_of(target, coordinates);
  motion.filter = source.filter;
  motion.iterations = Eigen::VectorXi::Zero(frames);
  motion.fit_seconds = Eigen::VectorXd::Zero(frames);
  ChainFitter evaluator(target, motion.setup);
  double aligned_squares = 0.0;
  int aligned_count = 0;
  motion.marker_errors.resize(frames, static_cast<Eigen::Index>(motion.setup.markers.size()));
  motion.rms_mm.resize(frames);
  motion.max_mm.resize(frames);
  motion.markers_used.resize(frames);
  for (Eigen::Index k = 0; k < frames; ++k) {
    Eigen::MatrixX3d targets(static_cast<Eigen::Index>(motion.setup.markers.size()), 3);
    for (std::size_t i = 0; i < motion.setup.markers.size(); ++i) {
      targets.row(static_cast<Eigen::Index>(i)) =
          trial.unit_to_mm * trial
                                 .position(source.trial_frames[static_cast<std::size_t>(k)],
                                           motion.setup.markers[i].trial)
                                 .transpose();
    }
    const ChainFitResult at = evaluator.evaluate(targets, coordinates.row(k).transpose());
    // The same without the frame's mean offset: how differently the
    // patient's body is configured, whatever the stride scaling did to
    // where it is.
    Eigen::Vector3d offset = Eigen::Vector3d::Zero();
    int present = 0;
    std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> pairs;
    for (std::size_t i = 0; i < motion.setup.markers.size(); ++i) {
      const Eigen::Vector3d measured = targets.row(static_cast<Eigen::Index>(i)).transpose();
      if (!measured.allFinite()) continue;
      const SkeletonMarker& marker =
          target.markers[static_cast<std::size_t>(motion.setup.markers[i].model)];
      const Eigen::Vector3d model =
          motion.poses[static_cast<std::size_t>(k)][static_cast<std::size_t>(marker.body)] *
          marker.local;
      pairs.emplace_back(model, measured);
      offset += model - measured;
      ++present;
    }
    if (present > 0) offset /= present;
    for (const auto& [model, measured] : pairs) {
      aligned_squares += (model - offset - measured).squaredNorm();
      ++aligned_count;
    }
    motion.marker_errors.row(k) = at.marker_errors.transpose();
    motion.rms_mm(k) = at.rms_mm;
    motion.max_mm(k) = at.max_mm;
    motion.markers_used(k) = at.markers_used;
  }
  result.aligned_marker_rms_mm =
      aligned_count > 0 ? std::sqrt(aligned_squares / aligned_count) : std::nan("");
  return result;
}

}  // namespace mmm::motion

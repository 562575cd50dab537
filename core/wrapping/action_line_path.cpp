#include "core/wrapping/action_line_path.h"

#include <algorithm>
#include <array>

#include "core/errors.h"

namespace mmm::wrapping {
namespace {

int body_of(const motion::Skeleton& skeleton, const std::string& bone, const std::string& what) {
  const std::optional<int> index = skeleton.body_index(bone);
  if (!index) {
    throw InvalidInputError(what + ": bone '" + bone + "' is not in the skeleton");
  }
  return *index;
}

double coordinate_value(const motion::Skeleton& skeleton, const Eigen::VectorXd& q,
                        const std::string& name, const std::string& what) {
  if (name.empty()) return 0.0;
  const std::optional<int> index = skeleton.coordinate_index(name);
  if (!index) {
    throw InvalidInputError(what + ": coordinate '" + name + "' is not in the skeleton");
  }
  return q(*index);
}

InvalidInputError unknown_obstacle(const std::string& what, const std::string& obstacle,
                                   const std::string& muscle) {
  return InvalidInputError{what + ": wrap obstacle '" + obstacle + "' is not one of muscle " +
                           muscle + "'s"};
}

Obstacle posed_obstacle(const atlas::WrapObstacle& source, const motion::SkeletonPose& pose,
                        const motion::Skeleton& skeleton, const std::string& what) {
  Obstacle obstacle;
  switch (source.shape) {
    case atlas::WrapShape::kSphere:
      obstacle.shape = ObstacleShape::kSphere;
      break;
    case atlas::WrapShape::kCylinder:
      obstacle.shape = ObstacleShape::kCylinder;
      break;
    case atlas::WrapShape::kEllipsoid:
      obstacle.shape = ObstacleShape::kEllipsoid;
      break;
  }
  obstacle.pose = pose.body_pose(body_of(skeleton, source.bone, what)) * source.pose;
  obstacle.radius = source.radii.x();
  obstacle.radii = source.radii;
  obstacle.quadrant = source.quadrant;
  return obstacle;
}

// Smoothstep from 0 at an end of the range to 1 at `blend` inside it.
double conditional_weight(double value, const std::array<double, 2>& range, double blend) {
  const double width = std::min(blend, 0.5 * (range[1] - range[0]));
  if (!(width > 0)) return 1.0;
  const double t = std::clamp(std::min(value - range[0], range[1] - value) / width, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

Eigen::Vector3d closest_on_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& p) {
  const Eigen::Vector3d ab = b - a;
  const double squared = ab.squaredNorm();
  if (squared <= 0) return a;
  return a + std::clamp((p - a).dot(ab) / squared, 0.0, 1.0) * ab;
}

}  // namespace

ActionLinePath action_line_path(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                                const atlas::ActionLine& line, const motion::Skeleton& skeleton,
                                const Eigen::VectorXd& q, const PathOptions& options) {
  const std::string what = "action line " + line.name;
  motion::SkeletonPose pose(skeleton);
  pose.set(q);
  std::vector<Eigen::Vector3d> anchors;
  std::vector<std::string> anchor_bones;
  std::vector<double> weights;  // 1 but for conditional points fading in
  ActionLinePath path;
  for (const atlas::PathPoint& point : line.points) {
    const int body = body_of(skeleton, point.bone, what + " point " + point.name);
    double weight = 1.0;
    if (point.kind == atlas::PathPointKind::kConditional) {
      const double value = coordinate_value(skeleton, q, point.coordinate, what);
      if (value < point.range[0] || value > point.range[1]) continue;
      weight = conditional_weight(value, point.range, options.conditional_blend);
    }
    Eigen::Vector3d local = point.position;
    if (point.kind == atlas::PathPointKind::kMoving) {
      const atlas::Bone* bone = atlas.find_bone(point.bone);
      Eigen::Vector3d in_bone;
      for (std::size_t k = 0; k < 3; ++k) {
        in_bone(static_cast<Eigen::Index>(k)) = point.moving_functions[k].evaluate(
            coordinate_value(skeleton, q, point.moving_coordinates[k], what));
      }
      local = (bone != nullptr ? bone->frame : Eigen::Isometry3d::Identity()) * in_bone;
    }
    anchors.push_back(pose.point(body, local));
    anchor_bones.push_back(point.bone);
    weights.push_back(weight);
    path.active.push_back(point.name);
  }
  if (anchors.size() < 2) {
    throw InvalidInputError(what + ": fewer than 2 path points are active at this pose");
  }
  // A fading conditional point moves from the segment between its
  // neighbours (weight 0) to its own place (weight 1).
  for (std::size_t i = 1; i + 1 < anchors.size(); ++i) {
    if (weights[i] >= 1.0) continue;
    const Eigen::Vector3d on_segment =
        closest_on_segment(anchors[i - 1], anchors[i + 1], anchors[i]);
    anchors[i] = on_segment + weights[i] * (anchors[i] - on_segment);
  }
  std::vector<Obstacle> obstacles;
  std::vector<std::string> obstacle_bones;
  for (const std::string& name : line.wrap_obstacles) {
    const auto found = std::find_if(muscle.wrap_obstacles.begin(), muscle.wrap_obstacles.end(),
                                    [&](const atlas::WrapObstacle& o) { return o.name == name; });
    if (found == muscle.wrap_obstacles.end()) {
      throw unknown_obstacle(what, name, muscle.name);
    }
    obstacles.push_back(posed_obstacle(*found, pose, skeleton, what));
    obstacle_bones.push_back(found->bone);
  }
  path.points.push_back(anchors.front());
  path.point_bones.push_back(anchor_bones.front());
  path.point_names.push_back(path.active.front());
  for (std::size_t i = 1; i < anchors.size(); ++i) {
    // The first listed obstacle this segment would pass through.
    WrapResult chosen;
    chosen.points = {anchors[i - 1], anchors[i]};
    chosen.length = (anchors[i] - anchors[i - 1]).norm();
    std::string wrapped_on;
    for (std::size_t o = 0; o < obstacles.size(); ++o) {
      const WrapResult wrap = wrap_segment(anchors[i - 1], anchors[i], obstacles[o], options.wrap);
      path.inside_obstacle = path.inside_obstacle || wrap.inside;
      if (wrap.wrapped) {
        chosen = wrap;
        wrapped_on = obstacle_bones[o];
        ++path.wraps;
        break;
      }
    }
    path.points.insert(path.points.end(), chosen.points.begin() + 1, chosen.points.end());
    path.point_bones.insert(path.point_bones.end(), chosen.points.size() - 2, wrapped_on);
    path.point_bones.push_back(anchor_bones[i]);
    path.point_names.insert(path.point_names.end(), chosen.points.size() - 2, std::string());
    path.point_names.push_back(path.active[i]);
    path.length += chosen.length;
  }
  return path;
}

double moment_arm(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                  const atlas::ActionLine& line, const motion::Skeleton& skeleton,
                  const Eigen::VectorXd& q, int coordinate, const PathOptions& options) {
  if (coordinate < 0 || coordinate >= skeleton.num_coordinates()) {
    throw InvalidInputError("moment arm of " + line.name + ": no coordinate " +
                            std::to_string(coordinate));
  }
  Eigen::VectorXd plus = q;
  Eigen::VectorXd minus = q;
  plus(coordinate) += options.derivative_step;
  minus(coordinate) -= options.derivative_step;
  const double longer = action_line_path(atlas, muscle, line, skeleton, plus, options).length;
  const double shorter = action_line_path(atlas, muscle, line, skeleton, minus, options).length;
  return -(longer - shorter) / (2.0 * options.derivative_step);
}

}  // namespace mmm::wrapping

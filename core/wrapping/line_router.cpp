#include "core/wrapping/line_router.h"

#include <set>
#include <string>
#include <utility>

#include "core/errors.h"

namespace mmm::wrapping {

LineRouter::LineRouter(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                       const atlas::ActionLine& line, const motion::Skeleton& skeleton,
                       std::vector<RoutingBone> bones, const RouterOptions& options)
    : atlas_(atlas),
      muscle_(muscle),
      line_(line),
      skeleton_(skeleton),
      bones_(std::move(bones)),
      options_(options) {
  if (!(options.moment_arm_step_rad > 0.0)) {
    throw InvalidInputError("path of " + line.name + ": moment_arm_step_rad must be > 0");
  }
  for (const RoutingBone& bone : bones_) {
    if (bone.sdf == nullptr || bone.body < 0 ||
        bone.body >= static_cast<int>(skeleton.bodies.size())) {
      throw InvalidInputError("path of " + line.name +
                              ": a routing bone without a surface or a skeleton body");
    }
  }
}

ActionLinePath LineRouter::global_route(const Eigen::VectorXd& q, const GlobalPath* warm,
                                        GlobalPath* result) const {
  // The path points in this pose (the obstacle-set path's named points;
  // its wraps are dropped: the bones themselves are the obstacles here).
  // Points that only follow the line (kFollowsLine) are left out: the
  // global path is the line of action itself.
  const ActionLinePath straight =
      action_line_path(atlas_, muscle_, line_, skeleton_, q, options_.path);
  std::set<std::string> followers;
  for (const atlas::PathPoint& point : line_.points) {
    if (point.kind == atlas::PathPointKind::kFollowsLine) followers.insert(point.name);
  }
  std::vector<Eigen::Vector3d> fixed;
  std::vector<std::string> names;
  std::vector<std::string> bones;
  for (std::size_t i = 0; i < straight.points.size(); ++i) {
    if (straight.point_names[i].empty() || followers.contains(straight.point_names[i])) continue;
    fixed.push_back(straight.points[i]);
    names.push_back(straight.point_names[i]);
    bones.push_back(straight.point_bones[i]);
  }
  motion::SkeletonPose pose(skeleton_);
  pose.set(q);
  std::vector<PosedSurface> surfaces;
  surfaces.reserve(bones_.size());
  for (const RoutingBone& bone : bones_) surfaces.push_back({bone.sdf, pose.body_pose(bone.body)});
  *result =
      global_path(fixed, surfaces, options_.global,
                  warm != nullptr && warm->segments.size() + 1 == fixed.size() ? warm : nullptr);
  ActionLinePath path;
  path.active = straight.active;
  path.inside_obstacle = false;
  path.length = result->length;
  for (std::size_t s = 0; s < result->segments.size(); ++s) {
    const GlobalSegment& segment = result->segments[s];
    if (s == 0) {
      path.points.push_back(segment.points.front());
      path.point_names.push_back(names[0]);
      path.point_bones.push_back(bones[0]);
    }
    // Interior points ride with the segment's first point's bone ("": the
    // binding carries them with the previous point).
    for (std::size_t i = 1; i + 1 < segment.points.size(); ++i) {
      path.points.push_back(segment.points[i]);
      path.point_names.emplace_back();
      path.point_bones.emplace_back();
    }
    path.points.push_back(segment.points.back());
    path.point_names.push_back(names[s + 1]);
    path.point_bones.push_back(bones[s + 1]);
    path.wraps += segment.touches ? 1 : 0;
    path.inside_obstacle = path.inside_obstacle || segment.start_inside || segment.end_inside;
  }
  return path;
}

ActionLinePath LineRouter::route(const Eigen::VectorXd& q) {
  if (options_.method == PathMethod::kObstacleSet) {
    return action_line_path(atlas_, muscle_, line_, skeleton_, q, options_.path);
  }
  GlobalPath result;
  ActionLinePath path = global_route(q, last_ ? &*last_ : nullptr, &result);
  last_contacts_ = 0;
  for (const GlobalSegment& segment : result.segments) last_contacts_ += segment.touches ? 1 : 0;
  last_ = std::move(result);
  return path;
}

double LineRouter::moment_arm(const Eigen::VectorXd& q, int coordinate) {
  if (options_.method == PathMethod::kObstacleSet) {
    return wrapping::moment_arm(atlas_, muscle_, line_, skeleton_, q, coordinate, options_.path);
  }
  if (coordinate < 0 || coordinate >= skeleton_.num_coordinates()) {
    throw InvalidInputError("moment arm of " + line_.name + ": no coordinate " +
                            std::to_string(coordinate));
  }
  const double step = options_.moment_arm_step_rad;
  Eigen::VectorXd plus = q;
  Eigen::VectorXd minus = q;
  plus(coordinate) += step;
  minus(coordinate) -= step;
  GlobalPath longer;
  GlobalPath shorter;
  const GlobalPath* warm = last_ ? &*last_ : nullptr;
  (void)global_route(plus, warm, &longer);
  (void)global_route(minus, warm, &shorter);
  return -(longer.length - shorter.length) / (2.0 * step);
}

}  // namespace mmm::wrapping

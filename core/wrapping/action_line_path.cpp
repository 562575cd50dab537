#include "core/wrapping/action_line_path.h"

#include <algorithm>
#include <array>
#include <cstddef>

#include <Eigen/Geometry>

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

// Where a point at `rest` relative to the rest segment a0-b0 lies relative to
// the segment a-b: same fraction along it, offset turned by the rotation
// taking the rest direction to the current one.
Eigen::Vector3d follow_segment(const Eigen::Vector3d& a0, const Eigen::Vector3d& b0,
                               const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               const Eigen::Vector3d& rest) {
  const Eigen::Vector3d d0 = b0 - a0;
  const Eigen::Vector3d d = b - a;
  if (d0.squaredNorm() <= 0 || d.squaredNorm() <= 0) return a + (rest - a0);
  const double t = (rest - a0).dot(d0) / d0.squaredNorm();
  const Eigen::Vector3d offset = rest - (a0 + t * d0);
  const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(d0, d);
  return a + t * d + turn * offset;
}

}  // namespace

ActionLinePath action_line_path(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                                const atlas::ActionLine& line, const motion::Skeleton& skeleton,
                                const Eigen::VectorXd& q, const PathOptions& options) {
  const std::string what = "action line " + line.name;
  motion::SkeletonPose pose(skeleton);
  pose.set(q);
  // Every point in order: where it is now and where it was at rest; an
  // inactive conditional point still has a place (its followers use it).
  struct Placed {
    Eigen::Vector3d now = Eigen::Vector3d::Zero();
    Eigen::Vector3d rest = Eigen::Vector3d::Zero();
    int body = 0;
    double weight = 1.0;  // < 1: a conditional point fading in
    bool follows = false;
    bool active = true;
  };
  std::vector<Placed> placed;
  placed.reserve(line.points.size());
  for (const atlas::PathPoint& point : line.points) {
    Placed p;
    p.rest = point.position;
    p.body = body_of(skeleton, point.bone, what + " point " + point.name);
    if (point.kind == atlas::PathPointKind::kFollowsLine) {
      p.follows = true;
      placed.push_back(p);
      continue;
    }
    if (point.kind == atlas::PathPointKind::kConditional) {
      const double value = coordinate_value(skeleton, q, point.coordinate, what);
      p.active = value >= point.range[0] && value <= point.range[1];
      if (p.active) p.weight = conditional_weight(value, point.range, options.conditional_blend);
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
    p.now = pose.point(p.body, local);
    placed.push_back(p);
  }
  // Followers keep their rest place relative to the segment between the
  // nearest always-active points around them (not conditional ones: their
  // segments may be short and switch): the fraction along it, and the
  // offset from it turned with it. Without such a point on one side, their
  // bone carries them.
  const auto fixed_neighbour = [&](std::size_t i, int step) {
    for (auto j = static_cast<std::ptrdiff_t>(i) + step;
         j >= 0 && j < static_cast<std::ptrdiff_t>(placed.size()); j += step) {
      const auto k = static_cast<std::size_t>(j);
      if (!placed[k].follows && line.points[k].kind != atlas::PathPointKind::kConditional) {
        return j;
      }
    }
    return std::ptrdiff_t{-1};
  };
  for (std::size_t i = 0; i < placed.size(); ++i) {
    if (!placed[i].follows) continue;
    const std::ptrdiff_t before = fixed_neighbour(i, -1);
    const std::ptrdiff_t after = fixed_neighbour(i, +1);
    if (before < 0 || after < 0) {
      placed[i].now = pose.point(placed[i].body, placed[i].rest);
      continue;
    }
    const Placed& a = placed[static_cast<std::size_t>(before)];
    const Placed& b = placed[static_cast<std::size_t>(after)];
    placed[i].now = follow_segment(a.rest, b.rest, a.now, b.now, placed[i].rest);
  }
  // A fading conditional point moves from the segment between the active
  // points next to it (weight 0: the path is as without it) to its own place
  // (weight 1). Its neighbours differ between the drawn path (followers
  // included) and the line of action (without them): one place for each.
  const auto faded = [&](bool with_followers) {
    std::vector<Eigen::Vector3d> places;
    places.reserve(placed.size());
    for (const Placed& p : placed) places.push_back(p.now);
    const auto counts = [&](std::size_t j) {
      return placed[j].active && (with_followers || !placed[j].follows);
    };
    const auto next_counted = [&](std::size_t i, int step) {
      for (auto j = static_cast<std::ptrdiff_t>(i) + step;
           j >= 0 && j < static_cast<std::ptrdiff_t>(placed.size()); j += step) {
        if (counts(static_cast<std::size_t>(j))) return j;
      }
      return std::ptrdiff_t{-1};
    };
    for (std::size_t i = 0; i < placed.size(); ++i) {
      if (!placed[i].active || placed[i].follows || placed[i].weight >= 1.0) continue;
      const std::ptrdiff_t before = next_counted(i, -1);
      const std::ptrdiff_t after = next_counted(i, +1);
      if (before < 0 || after < 0) continue;
      const Eigen::Vector3d on_segment =
          closest_on_segment(placed[static_cast<std::size_t>(before)].now,
                             placed[static_cast<std::size_t>(after)].now, placed[i].now);
      places[i] = on_segment + placed[i].weight * (placed[i].now - on_segment);
    }
    return places;
  };
  const bool has_followers = std::ranges::any_of(placed, [](const Placed& p) { return p.follows; });
  const std::vector<Eigen::Vector3d> drawn = faded(true);
  // Without followers the line of action is the drawn path (no second pass).
  const std::vector<Eigen::Vector3d> of_action = has_followers ? faded(false) : drawn;
  ActionLinePath path;
  std::vector<Eigen::Vector3d> anchors;
  std::vector<std::string> anchor_bones;
  for (std::size_t i = 0; i < placed.size(); ++i) {
    if (!placed[i].active) continue;
    anchors.push_back(drawn[i]);
    anchor_bones.push_back(line.points[i].bone);
    path.active.push_back(line.points[i].name);
  }
  if (anchors.size() < 2) {
    throw InvalidInputError(what + ": fewer than 2 path points are active at this pose");
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
  // The first listed obstacle the segment a-b would pass through, or the
  // straight segment.
  const auto wrapped = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           std::string& wrapped_on) {
    WrapResult chosen;
    chosen.points = {a, b};
    chosen.length = (b - a).norm();
    for (std::size_t o = 0; o < obstacles.size(); ++o) {
      WrapResult wrap = wrap_segment(a, b, obstacles[o], options.wrap);
      path.inside_obstacle = path.inside_obstacle || wrap.inside;
      if (wrap.wrapped) {
        wrapped_on = obstacle_bones[o];
        return wrap;
      }
    }
    return chosen;
  };
  path.points.push_back(anchors.front());
  path.point_bones.push_back(anchor_bones.front());
  path.point_names.push_back(path.active.front());
  for (std::size_t i = 1; i < anchors.size(); ++i) {
    std::string wrapped_on;
    const WrapResult chosen = wrapped(anchors[i - 1], anchors[i], wrapped_on);
    if (chosen.wrapped) ++path.wraps;
    path.points.insert(path.points.end(), chosen.points.begin() + 1, chosen.points.end());
    path.point_bones.insert(path.point_bones.end(), chosen.points.size() - 2, wrapped_on);
    path.point_bones.push_back(anchor_bones[i]);
    path.point_names.insert(path.point_names.end(), chosen.points.size() - 2, std::string());
    path.point_names.push_back(path.active[i]);
    path.length += chosen.length;
  }
  // The length (and so the moment arms) is the line of action's: the
  // model's points and their wraps, without the followers, which only bend
  // the drawn path through the muscle.
  std::vector<Eigen::Vector3d> mechanical;
  for (std::size_t i = 0; i < placed.size(); ++i) {
    if (placed[i].active && !placed[i].follows) mechanical.push_back(of_action[i]);
  }
  if (mechanical.size() != anchors.size()) {
    path.length = 0.0;
    for (std::size_t i = 1; i < mechanical.size(); ++i) {
      std::string ignored;
      path.length += wrapped(mechanical[i - 1], mechanical[i], ignored).length;
    }
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

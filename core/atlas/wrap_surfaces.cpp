#include "core/atlas/wrap_surfaces.h"

#include <algorithm>
#include <optional>
#include <set>

#include "core/errors.h"

namespace mmm::atlas {
namespace {

struct LineRef {
  Muscle* muscle = nullptr;
  ActionLine* line = nullptr;
};

LineRef find_line(Atlas& atlas, const std::string& name) {
  for (Muscle& muscle : atlas.muscles) {
    for (ActionLine& line : muscle.action_lines) {
      if (line.name == name) return {&muscle, &line};
    }
  }
  return {};
}

const PathPoint* find_point(const Atlas& atlas, const std::string& name) {
  for (const Muscle& muscle : atlas.muscles) {
    for (const ActionLine& line : muscle.action_lines) {
      for (const PathPoint& point : line.points) {
        if (point.name == name) return &point;
      }
    }
  }
  return nullptr;
}

// The first rotation axis of a joint that a coordinate drives (atlas frame);
// the joint frame's z for a joint without such an axis.
Eigen::Vector3d joint_axis(const Joint& joint) {
  for (const TransformAxis& axis : joint.axes) {
    if (axis.rotation && !axis.coordinate.empty()) {
      return (joint.parent_frame.linear() * axis.axis).normalized();
    }
  }
  return joint.parent_frame.linear().col(2);
}

[[noreturn]] void fail(const RecipeWrapSurface& surface, const std::string& problem) {
  throw InvalidInputError("wrap surface " + surface.name + ": " + problem);
}

}  // namespace

Eigen::Vector3d side_direction(const std::string& side) {
  if (side == "anterior") return Eigen::Vector3d::UnitY();
  if (side == "posterior") return -Eigen::Vector3d::UnitY();
  if (side == "superior") return Eigen::Vector3d::UnitZ();
  if (side == "inferior") return -Eigen::Vector3d::UnitZ();
  if (side == "right") return Eigen::Vector3d::UnitX();
  if (side == "left") return -Eigen::Vector3d::UnitX();
  throw InvalidInputError("wrap surface side '" + side +
                          "' is not anterior, posterior, superior, inferior, right or left");
}

std::vector<WrapSurfaceFitReport> add_wrap_surfaces(
    const AtlasRecipe& recipe, const std::map<std::string, mesh::IndexedMesh>& bone_meshes,
    Atlas& atlas) {
  std::vector<WrapSurfaceFitReport> reports;
  for (const RecipeWrapSurface& surface : recipe.wrap_surfaces) {
    const auto mesh = bone_meshes.find(surface.bone);
    if (mesh == bone_meshes.end()) fail(surface, "bone " + surface.bone + " has no surface");
    WrapSurfaceRegion region;
    region.radius_mm = surface.radius_mm;
    region.offset_mm = surface.offset_mm;
    std::optional<Eigen::Vector3d> side;
    if (!surface.side.empty()) side = side_direction(surface.side);
    if (!surface.around_joint.empty()) {
      // Around a joint the bone lies all round: the side picks its part.
      region.side = side;
      const Joint* joint = atlas.find_joint(surface.around_joint);
      if (joint == nullptr) fail(surface, "no joint " + surface.around_joint + " in the atlas");
      region.centre = joint->child_frame.translation();
    } else {
      const PathPoint* point = find_point(atlas, surface.around_point);
      if (point == nullptr) {
        fail(surface, "no path point " + surface.around_point + " in the atlas's action lines");
      }
      region.centre = point->position;
    }
    std::optional<Eigen::Vector3d> axis;
    if (!surface.axis_of_joint.empty()) {
      const Joint* joint = atlas.find_joint(surface.axis_of_joint);
      if (joint == nullptr) fail(surface, "no joint " + surface.axis_of_joint + " in the atlas");
      axis = joint_axis(*joint);
    }

    // The replaced points leave their lines; the others stay outside.
    std::vector<LineRef> lines;
    std::set<std::string> replaced;
    std::vector<NamedPoint> outside;
    for (const std::string& name : surface.lines) {
      const LineRef ref = find_line(atlas, name);
      if (ref.line == nullptr) fail(surface, "no action line " + name + " in the atlas");
      lines.push_back(ref);
      auto& points = ref.line->points;
      for (const std::string& gone : surface.replaces) {
        const auto at =
            std::ranges::find_if(points, [&](const PathPoint& p) { return p.name == gone; });
        if (at == points.end()) continue;
        if (at == points.begin() || std::next(at) == points.end()) {
          std::string problem = "it cannot replace ";
          problem += gone;
          problem += ", an end of line ";
          problem += name;
          fail(surface, problem);
        }
        points.erase(at);
        replaced.insert(gone);
      }
      for (const PathPoint& point : points) {
        if (point.kind != PathPointKind::kFollowsLine) {
          outside.push_back({point.name, point.position});
        }
      }
    }
    for (const std::string& gone : surface.replaces) {
      if (!replaced.contains(gone)) {
        fail(surface, "it replaces " + gone + ", which is not a point of its lines");
      }
    }

    WrapSurfaceFitReport report;
    const WrapObstacle obstacle =
        fit_wrap_surface(surface.name, surface.bone, surface.shape, mesh->second.V, region, side,
                         axis, outside, surface.clearance_mm, &report);
    for (const LineRef& ref : lines) {
      auto& obstacles = ref.muscle->wrap_obstacles;
      if (std::ranges::none_of(obstacles,
                               [&](const WrapObstacle& o) { return o.name == obstacle.name; })) {
        obstacles.push_back(obstacle);
      }
      ref.line->wrap_obstacles.push_back(obstacle.name);
    }
    reports.push_back(report);
  }
  return reports;
}

}  // namespace mmm::atlas

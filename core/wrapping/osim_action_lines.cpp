#include "core/wrapping/osim_action_lines.h"

#include "core/errors.h"

namespace mmm::wrapping {
namespace {

constexpr double kMmPerM = 1000.0;

opensim::Function in_mm(const opensim::Function& function) {
  return {opensim::MultiplierFunction(function, kMmPerM)};
}

}  // namespace

atlas::Atlas osim_action_lines(const opensim::OsimModel& model) {
  atlas::Atlas result;
  result.name = model.name;
  for (const opensim::Body& body : model.bodies) {
    if (body.is_ground) continue;
    atlas::Bone bone;
    bone.name = body.name;
    result.bones.push_back(bone);
  }
  for (const opensim::Muscle& source : model.muscles) {
    if (source.path_points.size() < 2) continue;
    atlas::Muscle muscle;
    muscle.name = source.name;
    atlas::ActionLine line;
    line.name = source.name;
    for (const opensim::PathPoint& from : source.path_points) {
      if (result.find_bone(from.frame.body) == nullptr) {
        throw InvalidInputError(model.source.string() + ": muscle " + source.name + " point " +
                                from.name + " is on '" + from.frame.body +
                                "', not on a moving body");
      }
      atlas::PathPoint point;
      point.name = from.name;
      point.bone = from.frame.body;
      point.position = kMmPerM * from.frame.to_body(from.location);
      if (from.kind == opensim::PathPointKind::kConditional) {
        point.kind = atlas::PathPointKind::kConditional;
        point.coordinate = from.coordinate;
        point.range = from.range;
        const opensim::Coordinate* coordinate = model.find_coordinate(from.coordinate);
        if (coordinate != nullptr &&
            coordinate->motion_type == opensim::MotionType::kTranslational) {
          point.range = {kMmPerM * from.range[0], kMmPerM * from.range[1]};
        }
      } else if (from.kind == opensim::PathPointKind::kMoving) {
        // The functions give the point in the point's frame; the atlas's
        // moving points are in the bone's frame, which here is the body.
        // gait2392's moving points (patella-like knee extensors) sit in
        // body frames, so the frame offset is the identity; others are
        // refused rather than misplaced.
        if (!from.frame.translation.isZero() || !from.frame.orientation.isZero()) {
          throw InvalidInputError(model.source.string() + ": muscle " + source.name +
                                  " moving point " + from.name +
                                  " is in an offset frame, which is not supported here");
        }
        point.kind = atlas::PathPointKind::kMoving;
        point.moving_coordinates = {from.x_coordinate, from.y_coordinate, from.z_coordinate};
        point.moving_functions = {in_mm(from.x_location), in_mm(from.y_location),
                                  in_mm(from.z_location)};
      }
      line.points.push_back(std::move(point));
    }
    muscle.action_lines.push_back(std::move(line));
    result.muscles.push_back(std::move(muscle));
  }
  return result;
}

}  // namespace mmm::wrapping

#include "core/atlas/opensim_mapping.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/atlas/bone_registration.h"
#include "core/errors.h"
#include "core/opensim/kinematics.h"

namespace mmm::atlas {
namespace {

const Eigen::Affine3d& body_map(const BodyMaps& maps, const std::string& body,
                                const std::string& what) {
  const auto it = maps.map.find(body);
  if (it == maps.map.end()) {
    throw InvalidInputError(what + ": OpenSim body '" + body +
                            "' is not registered into the atlas (add it under registration: "
                            "in the recipe)");
  }
  return it->second;
}

opensim::Function scaled_to_mm(const opensim::Function& function, double scale) {
  return {opensim::MultiplierFunction(function, scale)};
}

Coordinate map_coordinate(const opensim::Coordinate& source) {
  Coordinate coordinate;
  coordinate.name = source.name;
  double unit = 1.0;
  switch (source.motion_type) {
    case opensim::MotionType::kTranslational:
      coordinate.kind = CoordinateKind::kTranslational;
      unit = 1000.0;
      break;
    case opensim::MotionType::kCoupled:
      coordinate.kind = CoordinateKind::kCoupled;
      break;
    default:
      coordinate.kind = CoordinateKind::kRotational;
  }
  coordinate.range = {source.range[0] * unit, source.range[1] * unit};
  coordinate.default_value = source.default_value * unit;
  coordinate.rest_value = coordinate.default_value;
  return coordinate;
}

JointType joint_type_of(const std::string& element) {
  if (element == "CustomJoint") return JointType::kCustom;
  if (element == "PinJoint") return JointType::kPin;
  if (element == "BallJoint") return JointType::kBall;
  if (element == "WeldJoint") return JointType::kWeld;
  throw InvalidInputError("joint type " + element +
                          " is not supported in an atlas (CustomJoint, PinJoint, BallJoint, "
                          "WeldJoint are)");
}

// Residual of joint motion M(q) (translation scaled to mm) against `rest`:
// rotation vector (rad) and translation / 10 mm.
Eigen::Matrix<double, 6, 1> pose_residual(const opensim::Joint& joint,
                                          const opensim::CoordinateValues& values, double scale,
                                          const Eigen::Isometry3d& rest) {
  const Eigen::Isometry3d motion = opensim::joint_motion(joint, values);
  const Eigen::AngleAxisd rotation(motion.linear().transpose() * rest.linear());
  Eigen::Matrix<double, 6, 1> residual;
  residual.head<3>() = rotation.angle() * rotation.axis();
  residual.tail<3>() = (scale * motion.translation() - rest.translation()) / 10.0;
  return residual;
}

}  // namespace

double BodyMaps::scale(const std::string& body) const {
  return std::cbrt(std::abs(body_map(*this, body, "scale").linear().determinant()));
}

Eigen::Vector3d BodyMaps::point(const std::string& body, const Eigen::Vector3d& local) const {
  const auto pose_it = pose.find(body);
  if (pose_it == pose.end()) throw InvalidInputError("OpenSim body '" + body + "' has no pose");
  return body_map(*this, body, "point") * (pose_it->second * local);
}

Eigen::Isometry3d BodyMaps::frame(const std::string& body,
                                  const Eigen::Isometry3d& ground_frame) const {
  const Eigen::Affine3d& affine = body_map(*this, body, "frame");
  Eigen::Isometry3d mapped = Eigen::Isometry3d::Identity();
  mapped.linear() = nearest_rotation(affine.linear()) * ground_frame.linear();
  mapped.translation() = affine * ground_frame.translation();
  return mapped;
}

MappedJoint map_joint(const opensim::Joint& source, const BodyMaps& maps) {
  const std::string what = "joint " + source.name;
  body_map(maps, source.parent.body, what);
  body_map(maps, source.child.body, what);
  MappedJoint mapped;
  Joint& joint = mapped.joint;
  joint.name = source.name;
  joint.type = joint_type_of(source.type);
  joint.parent = maps.primary_bone.at(source.parent.body);
  joint.child = maps.primary_bone.at(source.child.body);
  const Eigen::Isometry3d parent_ground =
      maps.pose.at(source.parent.body) * opensim::frame_in_body(source.parent);
  const Eigen::Isometry3d child_ground =
      maps.pose.at(source.child.body) * opensim::frame_in_body(source.child);
  joint.parent_frame = maps.frame(source.parent.body, parent_ground);
  joint.child_frame = maps.frame(source.child.body, child_ground);
  const double scale = maps.scale(source.parent.body);
  for (const opensim::Coordinate& coordinate : source.coordinates) {
    joint.coordinates.push_back(map_coordinate(coordinate));
  }
  for (const opensim::TransformAxis& axis : source.spatial_transform) {
    TransformAxis mapped_axis;
    mapped_axis.rotation = axis.name.starts_with("rotation");
    mapped_axis.axis = axis.axis;
    mapped_axis.coordinate = axis.coordinates.empty() ? "" : axis.coordinates.front();
    mapped_axis.function =
        mapped_axis.rotation ? axis.function : scaled_to_mm(axis.function, scale);
    joint.axes.push_back(std::move(mapped_axis));
  }
  if (joint.type == JointType::kWeld || source.coordinates.empty()) return mapped;

  // Rest values: Gauss-Newton from the defaults, numeric Jacobian.
  const Eigen::Isometry3d rest = joint.parent_frame.inverse() * joint.child_frame;
  opensim::CoordinateValues values;
  for (const opensim::Coordinate& coordinate : source.coordinates) {
    values[coordinate.name] = coordinate.default_value;
  }
  const auto n = static_cast<Eigen::Index>(source.coordinates.size());
  for (int iteration = 0; iteration < 30; ++iteration) {
    const Eigen::Matrix<double, 6, 1> residual = pose_residual(source, values, scale, rest);
    Eigen::MatrixXd jacobian(6, n);
    for (Eigen::Index k = 0; k < n; ++k) {
      const std::string& name = source.coordinates[static_cast<std::size_t>(k)].name;
      constexpr double kStep = 1e-6;
      opensim::CoordinateValues moved = values;
      moved[name] += kStep;
      jacobian.col(k) = (pose_residual(source, moved, scale, rest) - residual) / kStep;
    }
    const Eigen::VectorXd step =
        (jacobian.transpose() * jacobian + 1e-9 * Eigen::MatrixXd::Identity(n, n))
            .ldlt()
            .solve(-jacobian.transpose() * residual);
    for (Eigen::Index k = 0; k < n; ++k) {
      values[source.coordinates[static_cast<std::size_t>(k)].name] += step(k);
    }
    if (step.norm() < 1e-10) break;
  }
  for (std::size_t k = 0; k < source.coordinates.size(); ++k) {
    const double unit = joint.coordinates[k].kind == CoordinateKind::kTranslational ? 1000.0 : 1.0;
    joint.coordinates[k].rest_value = values[source.coordinates[k].name] * unit;
  }
  const Eigen::Matrix<double, 6, 1> left = pose_residual(source, values, scale, rest);
  mapped.mismatch_deg = left.head<3>().norm() * 180.0 / std::numbers::pi;
  mapped.mismatch_mm = left.tail<3>().norm() * 10.0;
  return mapped;
}

ActionLine map_action_line(const opensim::OsimModel& model, const opensim::Muscle& muscle,
                           const BodyMaps& maps, const std::map<std::string, double>& rest,
                           std::vector<WrapObstacle>& obstacles, std::vector<std::string>& notes) {
  ActionLine line;
  line.name = muscle.name;
  const auto rest_of = [&](const std::string& coordinate) {
    const auto it = rest.find(coordinate);
    return it == rest.end() ? 0.0 : it->second;
  };
  for (const opensim::PathPoint& source : muscle.path_points) {
    const std::string what = "muscle " + muscle.name + " point " + source.name;
    const std::string& body = source.frame.body;
    body_map(maps, body, what);
    PathPoint point;
    point.name = source.name;
    point.bone = maps.primary_bone.at(body);
    Eigen::Vector3d local = opensim::frame_in_body(source.frame) * source.location;
    if (source.kind == opensim::PathPointKind::kConditional) {
      point.kind = PathPointKind::kConditional;
      point.coordinate = source.coordinate;
      point.range = source.range;
    } else if (source.kind == opensim::PathPointKind::kMoving) {
      point.kind = PathPointKind::kMoving;
      point.moving_coordinates = {source.x_coordinate, source.y_coordinate, source.z_coordinate};
      const double scale = maps.scale(body);
      point.moving_functions = {scaled_to_mm(source.x_location, scale),
                                scaled_to_mm(source.y_location, scale),
                                scaled_to_mm(source.z_location, scale)};
      local = opensim::frame_in_body(source.frame) *
              Eigen::Vector3d(source.x_location.evaluate(rest_of(source.x_coordinate)),
                              source.y_location.evaluate(rest_of(source.y_coordinate)),
                              source.z_location.evaluate(rest_of(source.z_coordinate)));
    }
    point.position = maps.point(body, local);
    line.points.push_back(std::move(point));
  }
  for (const opensim::PathWrap& wrap : muscle.path_wraps) {
    const opensim::WrapObject* object = model.find_wrap_object(wrap.wrap_object);
    if (object == nullptr || !object->active) continue;
    WrapShape shape = WrapShape::kSphere;
    switch (object->shape) {
      case opensim::WrapShape::kSphere:
        shape = WrapShape::kSphere;
        break;
      case opensim::WrapShape::kCylinder:
        shape = WrapShape::kCylinder;
        break;
      case opensim::WrapShape::kEllipsoid:
        shape = WrapShape::kEllipsoid;
        break;
      default:
        notes.push_back("wrap object " + object->name + " (" + object->type + ") of " +
                        muscle.name + " skipped: shape not supported");
        continue;
    }
    if (!maps.has(object->body)) continue;
    line.wrap_obstacles.push_back(object->name);
    if (std::ranges::any_of(obstacles,
                            [&](const WrapObstacle& o) { return o.name == object->name; })) {
      continue;
    }
    WrapObstacle obstacle;
    obstacle.name = object->name;
    obstacle.shape = shape;
    obstacle.bone = maps.primary_bone.at(object->body);
    Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
    local.linear() = opensim::rotation_xyz(object->xyz_body_rotation);
    local.translation() = object->translation;
    obstacle.pose = maps.frame(object->body, maps.pose.at(object->body) * local);
    const double scale = maps.scale(object->body);
    if (shape == WrapShape::kEllipsoid) {
      obstacle.radii = scale * object->dimensions;
    } else {
      obstacle.radii = Eigen::Vector3d(scale * object->radius, 0.0, scale * object->length);
    }
    obstacle.quadrant = object->quadrant;
    obstacles.push_back(std::move(obstacle));
  }
  return line;
}

}  // namespace mmm::atlas

#include "core/opensim/kinematics.h"

#include <deque>

#include "core/errors.h"

namespace mmm::opensim {
namespace {

double value_of(const std::string& coordinate, const Joint& joint, const CoordinateValues& values) {
  if (const auto given = values.find(coordinate); given != values.end()) return given->second;
  for (const Coordinate& c : joint.coordinates) {
    if (c.name == coordinate) return c.default_value;
  }
  throw InvalidInputError("joint '" + joint.name + "': transform axis uses coordinate '" +
                          coordinate + "', which the joint does not define");
}

double axis_value(const TransformAxis& axis, const Joint& joint, const CoordinateValues& values) {
  const double q =
      axis.coordinates.empty() ? 0.0 : value_of(axis.coordinates.front(), joint, values);
  return axis.function.evaluate(q);
}

Eigen::Isometry3d custom_motion(const Joint& joint, const CoordinateValues& values) {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  for (const TransformAxis& axis : joint.spatial_transform) {
    const double amount = axis_value(axis, joint, values);
    const Eigen::Vector3d direction = axis.axis.normalized();
    if (axis.name.starts_with("rotation")) {
      rotation = rotation * Eigen::AngleAxisd(amount, direction).toRotationMatrix();
    } else {
      translation += amount * direction;
    }
  }
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = rotation;
  motion.translation() = translation;
  return motion;
}

double coordinate_value(const Joint& joint, std::size_t index, const CoordinateValues& values) {
  if (index >= joint.coordinates.size()) return 0.0;
  return value_of(joint.coordinates[index].name, joint, values);
}

}  // namespace

Eigen::Isometry3d frame_in_body(const FrameRef& frame) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = frame.rotation();
  pose.translation() = frame.translation;
  return pose;
}

Eigen::Isometry3d joint_motion(const Joint& joint, const CoordinateValues& values) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  if (joint.type == "CustomJoint") return custom_motion(joint, values);
  if (joint.type == "WeldJoint") return motion;
  if (joint.type == "PinJoint") {
    motion.linear() =
        Eigen::AngleAxisd(coordinate_value(joint, 0, values), Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    return motion;
  }
  if (joint.type == "BallJoint" || joint.type == "FreeJoint") {
    const Eigen::Vector3d angles(coordinate_value(joint, 0, values),
                                 coordinate_value(joint, 1, values),
                                 coordinate_value(joint, 2, values));
    motion.linear() = rotation_xyz(angles);
    if (joint.type == "FreeJoint") {
      motion.translation() =
          Eigen::Vector3d(coordinate_value(joint, 3, values), coordinate_value(joint, 4, values),
                          coordinate_value(joint, 5, values));
    }
    return motion;
  }
  throw InvalidInputError("joint '" + joint.name + "' of type " + joint.type +
                          " is not supported by the kinematics (CustomJoint, WeldJoint, PinJoint, "
                          "BallJoint and FreeJoint are)");
}

std::map<std::string, Eigen::Isometry3d> body_poses(const OsimModel& model,
                                                    const CoordinateValues& values) {
  std::map<std::string, Eigen::Isometry3d> poses;
  for (const Body& body : model.bodies) {
    if (body.is_ground) poses[body.name] = Eigen::Isometry3d::Identity();
  }
  if (poses.empty()) poses["ground"] = Eigen::Isometry3d::Identity();
  // Joints may come in any order: place a child once its parent is placed.
  std::deque<const Joint*> pending;
  for (const Joint& joint : model.joints) pending.push_back(&joint);
  std::size_t stalled = 0;
  while (!pending.empty() && stalled <= pending.size()) {
    const Joint* joint = pending.front();
    pending.pop_front();
    const auto parent = poses.find(joint->parent.body);
    if (parent == poses.end()) {
      pending.push_back(joint);
      ++stalled;
      continue;
    }
    stalled = 0;
    poses[joint->child.body] = parent->second * frame_in_body(joint->parent) *
                               joint_motion(*joint, values) * frame_in_body(joint->child).inverse();
  }
  if (!pending.empty()) {
    throw InvalidInputError("joint '" + pending.front()->name + "' hangs from body '" +
                            pending.front()->parent.body +
                            "', which no chain of joints connects to the ground");
  }
  for (const Body& body : model.bodies) {
    if (!poses.contains(body.name)) {
      throw InvalidInputError("body '" + body.name + "' has no joint connecting it to the ground");
    }
  }
  return poses;
}

}  // namespace mmm::opensim

#include "core/motion/skeleton.h"

#include <cmath>
#include <map>
#include <numbers>

#include "core/atlas/kinematic_chain.h"
#include "core/errors.h"
#include "core/opensim/kinematics.h"

namespace mmm::motion {
namespace {

constexpr double kMmPerM = 1000.0;

Eigen::Isometry3d frame_in_body_mm(const opensim::FrameRef& frame) {
  Eigen::Isometry3d pose = opensim::frame_in_body(frame);
  pose.translation() *= kMmPerM;
  return pose;
}

SkeletonAxis identity_axis(bool rotation, const Eigen::Vector3d& direction, int coordinate) {
  SkeletonAxis axis;
  axis.rotation = rotation;
  axis.direction = direction;
  axis.coordinate = coordinate;
  axis.function = opensim::LinearFunction{1.0, 0.0};
  return axis;
}

int coordinate_or_throw(const Skeleton& skeleton, const std::string& coordinate,
                        const std::string& joint) {
  const std::optional<int> index = skeleton.coordinate_index(coordinate);
  if (!index) {
    throw InvalidInputError("joint '" + joint + "': a transform axis uses coordinate '" +
                            coordinate + "', which no joint defines");
  }
  return *index;
}

// The axes of an OpenSim joint; coordinates are already in `skeleton`.
std::vector<SkeletonAxis> osim_axes(const opensim::Joint& joint, const Skeleton& skeleton,
                                    int first_coordinate) {
  std::vector<SkeletonAxis> axes;
  const auto coordinate_of = [&](std::size_t k) {
    if (k >= joint.coordinates.size()) {
      throw InvalidInputError("joint '" + joint.name + "' of type " + joint.type + " needs " +
                              std::to_string(k + 1) + " coordinates, it defines " +
                              std::to_string(joint.coordinates.size()));
    }
    return first_coordinate + static_cast<int>(k);
  };
  if (joint.type == "WeldJoint") return axes;
  if (joint.type == "PinJoint") {
    axes.push_back(identity_axis(true, Eigen::Vector3d::UnitZ(), coordinate_of(0)));
    return axes;
  }
  if (joint.type == "BallJoint" || joint.type == "FreeJoint") {
    for (int k = 0; k < 3; ++k) {
      axes.push_back(identity_axis(true, Eigen::Vector3d::Unit(k), coordinate_of(k)));
    }
    if (joint.type == "FreeJoint") {
      for (int k = 0; k < 3; ++k) {
        axes.push_back(identity_axis(false, Eigen::Vector3d::Unit(k), coordinate_of(k + 3)));
      }
    }
    return axes;
  }
  if (joint.type != "CustomJoint") {
    throw InvalidInputError("joint '" + joint.name + "' of type " + joint.type +
                            " has no kinematics here (CustomJoint, WeldJoint, PinJoint, "
                            "BallJoint and FreeJoint have)");
  }
  for (const opensim::TransformAxis& source : joint.spatial_transform) {
    SkeletonAxis axis;
    axis.rotation = source.name.starts_with("rotation");
    if (source.axis.norm() == 0.0) {
      throw InvalidInputError("joint '" + joint.name + "': " + source.name + " has a zero axis");
    }
    axis.direction = source.axis.normalized();
    axis.function = source.function;
    if (!source.coordinates.empty()) {
      axis.coordinate = coordinate_or_throw(skeleton, source.coordinates.front(), joint.name);
      if (skeleton.coordinates[static_cast<std::size_t>(axis.coordinate)].unit ==
          CoordinateUnit::kLength) {
        axis.in_scale = 1.0 / kMmPerM;
      }
    }
    if (!axis.rotation) axis.out_scale = kMmPerM;
    axes.push_back(std::move(axis));
  }
  return axes;
}

SkeletonCoordinate osim_coordinate(const opensim::Coordinate& source) {
  SkeletonCoordinate coordinate;
  coordinate.name = source.name;
  const bool length = source.motion_type == opensim::MotionType::kTranslational;
  const double unit = length ? kMmPerM : 1.0;
  coordinate.unit = length ? CoordinateUnit::kLength : CoordinateUnit::kAngle;
  coordinate.lower = source.range[0] * unit;
  coordinate.upper = source.range[1] * unit;
  coordinate.clamped = source.clamped;
  coordinate.locked = source.locked;
  coordinate.default_value = source.default_value * unit;
  return coordinate;
}

SkeletonCoordinate atlas_coordinate(const atlas::Coordinate& source) {
  SkeletonCoordinate coordinate;
  coordinate.name = source.name;
  coordinate.unit = source.kind == atlas::CoordinateKind::kTranslational ? CoordinateUnit::kLength
                                                                         : CoordinateUnit::kAngle;
  coordinate.lower = source.range[0];
  coordinate.upper = source.range[1];
  coordinate.default_value = source.default_value;
  return coordinate;
}

std::vector<SkeletonAxis> atlas_axes(const atlas::Joint& joint, const Skeleton& skeleton,
                                     int first_coordinate) {
  std::vector<SkeletonAxis> axes;
  switch (joint.type) {
    case atlas::JointType::kWeld:
      return axes;
    case atlas::JointType::kPin:
      axes.push_back(identity_axis(true, Eigen::Vector3d::UnitZ(), first_coordinate));
      return axes;
    case atlas::JointType::kBall:
      for (int k = 0; k < 3; ++k) {
        axes.push_back(identity_axis(true, Eigen::Vector3d::Unit(k), first_coordinate + k));
      }
      return axes;
    case atlas::JointType::kCustom:
      break;
  }
  for (const atlas::TransformAxis& source : joint.axes) {
    SkeletonAxis axis;
    axis.rotation = source.rotation;
    if (source.axis.norm() == 0.0) {
      throw InvalidInputError("joint '" + joint.name + "': a transform axis is zero");
    }
    axis.direction = source.axis.normalized();
    axis.function = source.function;
    if (!source.coordinate.empty()) {
      axis.coordinate = coordinate_or_throw(skeleton, source.coordinate, joint.name);
    }
    axes.push_back(std::move(axis));
  }
  return axes;
}

Eigen::Isometry3d motion_of(const std::vector<SkeletonAxis>& axes, const Eigen::VectorXd& q) {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  for (const SkeletonAxis& axis : axes) {
    const double amount = axis.value(axis.coordinate < 0 ? 0.0 : q(axis.coordinate));
    if (axis.rotation) {
      rotation = rotation * Eigen::AngleAxisd(amount, axis.direction).toRotationMatrix();
    } else {
      translation += amount * axis.direction;
    }
  }
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = rotation;
  motion.translation() = translation;
  return motion;
}

}  // namespace

std::optional<int> Skeleton::body_index(std::string_view body) const {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == body) return static_cast<int>(i);
  }
  return std::nullopt;
}

std::optional<int> Skeleton::coordinate_index(std::string_view coordinate) const {
  for (std::size_t i = 0; i < coordinates.size(); ++i) {
    if (coordinates[i].name == coordinate) return static_cast<int>(i);
  }
  return std::nullopt;
}

std::optional<int> Skeleton::marker_index(std::string_view marker) const {
  for (std::size_t i = 0; i < markers.size(); ++i) {
    if (markers[i].name == marker) return static_cast<int>(i);
  }
  return std::nullopt;
}

Eigen::VectorXd Skeleton::default_coordinates() const {
  Eigen::VectorXd q(num_coordinates());
  for (int i = 0; i < num_coordinates(); ++i) {
    q(i) = coordinates[static_cast<std::size_t>(i)].default_value;
  }
  return q;
}

std::vector<int> Skeleton::bodies_moved_by(int coordinate) const {
  std::vector<bool> moved(bodies.size(), false);
  std::vector<int> result;
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    bool own = false;
    for (const SkeletonAxis& axis : bodies[b].axes) own = own || axis.coordinate == coordinate;
    const int parent = bodies[b].parent;
    moved[b] = own || (parent >= 0 && moved[static_cast<std::size_t>(parent)]);
    if (moved[b]) result.push_back(static_cast<int>(b));
  }
  return result;
}

Skeleton skeleton_from_osim(const opensim::OsimModel& model) {
  Skeleton skeleton;
  skeleton.name = model.name;
  std::map<std::string, int> placed;  // body -> index; the ground is -1
  for (const opensim::Body& body : model.bodies) {
    if (body.is_ground) placed[body.name] = -1;
  }
  if (placed.empty()) placed["ground"] = -1;
  std::vector<const opensim::Joint*> pending;
  pending.reserve(model.joints.size());
  for (const opensim::Joint& joint : model.joints) pending.push_back(&joint);
  bool progress = true;
  while (!pending.empty() && progress) {
    progress = false;
    for (auto it = pending.begin(); it != pending.end();) {
      const opensim::Joint& joint = **it;
      const auto parent = placed.find(joint.parent.body);
      if (parent == placed.end()) {
        ++it;
        continue;
      }
      const int first_coordinate = skeleton.num_coordinates();
      for (const opensim::Coordinate& coordinate : joint.coordinates) {
        skeleton.coordinates.push_back(osim_coordinate(coordinate));
      }
      SkeletonBody body;
      body.name = joint.child.body;
      body.parent = parent->second;
      body.joint = joint.name;
      body.parent_offset = frame_in_body_mm(joint.parent);
      body.child_offset = frame_in_body_mm(joint.child);
      body.axes = osim_axes(joint, skeleton, first_coordinate);
      placed[body.name] = static_cast<int>(skeleton.bodies.size());
      skeleton.bodies.push_back(std::move(body));
      it = pending.erase(it);
      progress = true;
    }
  }
  if (!pending.empty()) {
    throw InvalidInputError(model.source.string() + ": joint '" + pending.front()->name +
                            "' hangs from body '" + pending.front()->parent.body +
                            "', which no chain of joints connects to the ground");
  }
  for (const opensim::Body& body : model.bodies) {
    if (!body.is_ground && !placed.contains(body.name)) {
      throw InvalidInputError(model.source.string() + ": body '" + body.name +
                              "' has no joint connecting it to the ground");
    }
  }
  for (const opensim::Marker& marker : model.markers) {
    const auto body = placed.find(marker.frame.body);
    if (body == placed.end() || body->second < 0) continue;  // on the ground: not tracked
    Eigen::Vector3d local = kMmPerM * marker.frame.to_body(marker.location);
    skeleton.markers.push_back({marker.name, body->second, local, marker.fixed});
  }
  return skeleton;
}

Skeleton skeleton_from_atlas(const atlas::Atlas& atlas) {
  Skeleton skeleton;
  skeleton.name = atlas.name;
  const std::vector<const atlas::Bone*> order = atlas::chain_order(atlas, "motion skeleton");
  std::map<std::string, int> placed;
  for (const atlas::Bone* bone : order) {
    SkeletonBody body;
    body.name = bone->name;
    const atlas::Joint* joint = atlas::joint_to(atlas, bone->name);
    if (joint == nullptr) {
      // The root: gait2392's ground_pelvis on the bone's own frame.
      const int first = skeleton.num_coordinates();
      const double half_pi = std::numbers::pi / 2.0;
      const std::string& root = bone->name;
      skeleton.coordinates.push_back(
          {root + "_tilt", CoordinateUnit::kAngle, -half_pi, half_pi, false, false, 0.0});
      skeleton.coordinates.push_back(
          {root + "_list", CoordinateUnit::kAngle, -half_pi, half_pi, false, false, 0.0});
      skeleton.coordinates.push_back({root + "_rotation", CoordinateUnit::kAngle, -std::numbers::pi,
                                      std::numbers::pi, false, false, 0.0});
      for (const char* axis : {"_tx", "_ty", "_tz"}) {
        skeleton.coordinates.push_back(
            {root + axis, CoordinateUnit::kLength, -1e4, 1e4, false, false, 0.0});
      }
      body.joint = "ground_" + root;
      body.axes = {identity_axis(true, Eigen::Vector3d::UnitZ(), first),
                   identity_axis(true, Eigen::Vector3d::UnitX(), first + 1),
                   identity_axis(true, Eigen::Vector3d::UnitY(), first + 2),
                   identity_axis(false, Eigen::Vector3d::UnitX(), first + 3),
                   identity_axis(false, Eigen::Vector3d::UnitY(), first + 4),
                   identity_axis(false, Eigen::Vector3d::UnitZ(), first + 5)};
      body.child_offset = bone->frame;
    } else {
      body.parent = placed.at(joint->parent);
      body.joint = joint->name;
      if (joint->type != atlas::JointType::kWeld) {
        const int first = skeleton.num_coordinates();
        Eigen::VectorXd rest(first + static_cast<int>(joint->coordinates.size()));
        rest.setZero();
        for (const atlas::Coordinate& coordinate : joint->coordinates) {
          rest(skeleton.num_coordinates()) = coordinate.rest_value;
          skeleton.coordinates.push_back(atlas_coordinate(coordinate));
        }
        body.axes = atlas_axes(*joint, skeleton, first);
        body.parent_offset = joint->parent_frame;
        body.child_offset = joint->parent_frame * motion_of(body.axes, rest);
      }
    }
    placed[bone->name] = static_cast<int>(skeleton.bodies.size());
    skeleton.bodies.push_back(std::move(body));
  }
  for (const atlas::Marker& marker : atlas.markers) {
    const auto body = placed.find(marker.bone);
    if (body == placed.end()) {
      throw InvalidInputError("atlas marker '" + marker.name + "' is on bone '" + marker.bone +
                              "', which the atlas does not have");
    }
    skeleton.markers.push_back({marker.name, body->second, marker.position, marker.fixed});
  }
  return skeleton;
}

Eigen::Isometry3d joint_motion(const SkeletonBody& body, const Eigen::VectorXd& q) {
  return motion_of(body.axes, q);
}

SkeletonPose::SkeletonPose(const Skeleton& skeleton)
    : skeleton_(&skeleton),
      world_(skeleton.bodies.size(), Eigen::Isometry3d::Identity()),
      axes_(skeleton.bodies.size()) {
  for (std::size_t b = 0; b < skeleton.bodies.size(); ++b) {
    axes_[b].resize(skeleton.bodies[b].axes.size());
  }
}

void SkeletonPose::set(const Eigen::VectorXd& q) {
  if (q.size() != skeleton_->num_coordinates()) {
    throw InvalidInputError("skeleton '" + skeleton_->name + "': " + std::to_string(q.size()) +
                            " coordinate values given, it has " +
                            std::to_string(skeleton_->num_coordinates()));
  }
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    if (!std::isfinite(q(i))) {
      throw InvalidInputError("skeleton '" + skeleton_->name + "': coordinate '" +
                              skeleton_->coordinates[static_cast<std::size_t>(i)].name +
                              "' is not finite");
    }
  }
  for (std::size_t b = 0; b < skeleton_->bodies.size(); ++b) {
    const SkeletonBody& body = skeleton_->bodies[b];
    const Eigen::Isometry3d frame =
        (body.parent < 0 ? Eigen::Isometry3d::Identity() : world_[body_i(body.parent)]) *
        body.parent_offset;
    Eigen::Vector3d translation = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < body.axes.size(); ++k) {
      const SkeletonAxis& axis = body.axes[k];
      if (axis.rotation) continue;
      const double value = axis.coordinate < 0 ? 0.0 : q(axis.coordinate);
      translation += axis.value(value) * axis.direction;
      axes_[b][k] = {false, frame.linear() * axis.direction, Eigen::Vector3d::Zero(),
                     axis.coordinate, axis.coordinate < 0 ? 0.0 : axis.derivative(value)};
    }
    const Eigen::Vector3d pivot = frame * translation;
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    for (std::size_t k = 0; k < body.axes.size(); ++k) {
      const SkeletonAxis& axis = body.axes[k];
      if (!axis.rotation) continue;
      const double value = axis.coordinate < 0 ? 0.0 : q(axis.coordinate);
      axes_[b][k] = {true, frame.linear() * rotation * axis.direction, pivot, axis.coordinate,
                     axis.coordinate < 0 ? 0.0 : axis.derivative(value)};
      rotation = rotation * Eigen::AngleAxisd(axis.value(value), axis.direction).toRotationMatrix();
    }
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    motion.linear() = rotation;
    motion.translation() = translation;
    world_[b] = frame * motion * body.child_offset.inverse();
  }
}

Eigen::Vector3d SkeletonPose::marker(int marker) const {
  const SkeletonMarker& m = skeleton_->markers.at(static_cast<std::size_t>(marker));
  return world_[body_i(m.body)] * m.local;
}

void SkeletonPose::add_point_jacobian(int body, const Eigen::Vector3d& world_point, double weight,
                                      Eigen::Ref<Eigen::MatrixXd> jacobian,
                                      Eigen::Index row) const {
  for (int b = body; b >= 0; b = skeleton_->bodies[body_i(b)].parent) {
    for (const WorldAxis& axis : axes_[body_i(b)]) {
      if (axis.coordinate < 0 || axis.rate == 0.0) continue;
      const Eigen::Vector3d velocity =
          axis.rotation ? Eigen::Vector3d(axis.direction.cross(world_point - axis.origin))
                        : axis.direction;
      jacobian.block<3, 1>(row, axis.coordinate) += weight * axis.rate * velocity;
    }
  }
}

}  // namespace mmm::motion

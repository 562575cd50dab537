#pragma once
// The kinematic tree that motion fusion drives: bodies connected by joints
// whose motion is a function of named coordinates, markers fixed to bodies,
// and the forward kinematics with its exact Jacobian. Built from an OpenSim
// model (metres -> mm) or from an mmm atlas, so that the same chain fit runs
// on OpenSim's own subject model (to compare with OpenSim's inverse
// kinematics) and on a patient's scaled atlas.
//
// Units: mm for lengths and translational coordinates, rad for rotational
// and coupled coordinates. Every pose is body -> world.
//
// Joint motion, as OpenSim's CustomJoint / SpatialTransform:
//   W_child = W_parent * P * M(q) * C^-1
//   M(q)    = Translate(sum_k f_k(q) d_k) * Rot(f_1(q), d_1) Rot(f_2(q), d_2) Rot(f_3(q), d_3)
// P and C are the joint's frames in the parent and child bodies; the
// rotations are body-fixed (each about its axis as carried by the ones
// before); the translations are along their axes in P. Pin, ball and free
// joints are the special cases OpenSim defines (z; X-Y-Z; X-Y-Z + x, y, z).
//
// Jacobian (exact, no differencing): a coordinate moves every point x of the
// bodies distal to its joint by
//   dx/dq = f'(q) d_w              for a translation axis (d_w its world direction)
//   dx/dq = f'(q) a_w x (x - o_w)  for a rotation axis through o_w along a_w
// summed over every axis the coordinate drives (the knee's coupled
// translations included).

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/opensim/opensim_function.h"
#include "core/opensim/osim_model.h"

namespace mmm::motion {

enum class CoordinateUnit { kAngle, kLength };  // rad; mm

struct SkeletonCoordinate {
  std::string name;
  CoordinateUnit unit = CoordinateUnit::kAngle;
  double lower = 0.0;  // range (rad or mm)
  double upper = 0.0;
  bool clamped = true;  // the range is a joint limit the fit must respect
  bool locked = false;  // held at default_value
  double default_value = 0.0;
};

// One transform axis: the joint moves by out_scale * f(in_scale * q) (rad or
// mm) about (rotation) or along (translation) `direction`, a unit vector in
// the joint's parent frame. in/out scales carry unit changes (an OpenSim
// translation function in m of a coordinate in m becomes mm of mm).
struct SkeletonAxis {
  bool rotation = true;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  int coordinate = -1;  // index into Skeleton::coordinates; -1: constant f(0)
  opensim::Function function;
  double in_scale = 1.0;
  double out_scale = 1.0;

  [[nodiscard]] double value(double q) const { return out_scale * function.evaluate(in_scale * q); }
  [[nodiscard]] double derivative(double q) const {
    return out_scale * in_scale * function.derivative(in_scale * q);
  }
};

struct SkeletonBody {
  std::string name;
  int parent = -1;    // index into Skeleton::bodies (always before this one); -1: the world
  std::string joint;  // the joint that moves it
  Eigen::Isometry3d parent_offset = Eigen::Isometry3d::Identity();  // P, in the parent (mm)
  Eigen::Isometry3d child_offset = Eigen::Isometry3d::Identity();   // C, in this body (mm)
  std::vector<SkeletonAxis> axes;  // rotations first, in order; empty: welded
};

struct SkeletonMarker {
  std::string name;
  int body = 0;
  Eigen::Vector3d local = Eigen::Vector3d::Zero();  // in the body (mm)
  bool fixed = false;                               // OpenSim: not moved by marker placement
};

struct Skeleton {
  std::string name;
  std::vector<SkeletonBody> bodies;  // parents before children
  std::vector<SkeletonCoordinate> coordinates;
  std::vector<SkeletonMarker> markers;

  [[nodiscard]] int num_coordinates() const { return static_cast<int>(coordinates.size()); }
  // Indices by exact name; nullopt when absent.
  [[nodiscard]] std::optional<int> body_index(std::string_view body) const;
  [[nodiscard]] std::optional<int> coordinate_index(std::string_view coordinate) const;
  [[nodiscard]] std::optional<int> marker_index(std::string_view marker) const;
  // Every coordinate's default value.
  [[nodiscard]] Eigen::VectorXd default_coordinates() const;
  // The bodies whose pose `coordinate` changes (distal to its joint).
  [[nodiscard]] std::vector<int> bodies_moved_by(int coordinate) const;
};

// From an OpenSim model: every body but the ground, every coordinate (locked
// and clamped flags kept), every marker. Lengths become mm.
// Throws InvalidInputError when a body is not connected to the ground, a
// joint type has no kinematics (CustomJoint, WeldJoint, PinJoint, BallJoint,
// FreeJoint have), or an axis names a coordinate its joint does not define.
Skeleton skeleton_from_osim(const opensim::OsimModel& model);

// From an atlas. A body's frame is the atlas frame at rest, so a body pose
// maps rest-pose atlas coordinates (mm) to the world and the atlas's markers,
// landmarks and path points need no conversion. The root bone gets
// gait2392's ground-pelvis joint (pelvis_tilt about z, pelvis_list about x,
// pelvis_rotation about y, then pelvis_tx/ty/tz; an OpenSim world: y up)
// acting on the root bone's own frame, so pelvis angles keep OpenSim's
// meaning. Each other joint takes its rest-pose child frame as
// C = P * M(q_rest): at the rest values every bone is exactly where the
// atlas has it (the atlas's joint frames match M(q_rest) only to ~1 mm /
// 4 degrees, see the atlas build report), and the joint axes are OpenSim's.
// Throws InvalidInputError when the atlas has no root or a bone is not
// connected to it, or an axis names a coordinate its joint does not define.
Skeleton skeleton_from_atlas(const atlas::Atlas& atlas);

// Forward kinematics and, optionally, the Jacobian of world points.
class SkeletonPose {
 public:
  explicit SkeletonPose(const Skeleton& skeleton);

  // Places every body for coordinates q (#coordinates). Throws
  // InvalidInputError for a wrong size or a non-finite value.
  void set(const Eigen::VectorXd& q);

  [[nodiscard]] const Eigen::Isometry3d& body_pose(int body) const { return world_[body_i(body)]; }
  [[nodiscard]] const std::vector<Eigen::Isometry3d>& body_poses() const { return world_; }
  [[nodiscard]] Eigen::Vector3d point(int body, const Eigen::Vector3d& local) const {
    return world_[body_i(body)] * local;
  }
  [[nodiscard]] Eigen::Vector3d marker(int marker) const;

  // d(world point)/dq of the point `world_point` fixed to `body`, added into
  // rows row..row+2 of `jacobian` (#rows by #coordinates) times `weight`.
  void add_point_jacobian(int body, const Eigen::Vector3d& world_point, double weight,
                          Eigen::Ref<Eigen::MatrixXd> jacobian, Eigen::Index row) const;

  [[nodiscard]] const Skeleton& skeleton() const { return *skeleton_; }

 private:
  // One axis at the current pose: world direction, a world point on it
  // (rotations), the coordinate and df/dq.
  struct WorldAxis {
    bool rotation = true;
    Eigen::Vector3d direction;
    Eigen::Vector3d origin;
    int coordinate = -1;
    double rate = 0.0;
  };
  [[nodiscard]] static std::size_t body_i(int body) { return static_cast<std::size_t>(body); }

  const Skeleton* skeleton_;
  std::vector<Eigen::Isometry3d> world_;
  std::vector<std::vector<WorldAxis>> axes_;  // per body, its joint's axes
};

// M(q) of one body's joint at coordinates q (the joint's own motion, P to C).
Eigen::Isometry3d joint_motion(const SkeletonBody& body, const Eigen::VectorXd& q);

}  // namespace mmm::motion

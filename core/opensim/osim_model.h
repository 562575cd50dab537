#pragma once
// OpenSim model files (.osim, the XML of OpenSim 4.x; the 3.x layout is read
// where it differs cheaply): bodies with their bone meshes and wrap objects,
// joints with their coordinates and CustomJoint spatial transforms, model
// markers, and muscles (any force with a GeometryPath) with their path
// points and wrap references.
//
// Plain data, in the units of the file: OpenSim models use metres, radians,
// kilograms and newtons. Every position below is expressed in the frame
// named beside it. Body-fixed rotations ("orientation", "xyz_body_rotation")
// are X-Y-Z body-fixed Euler angles: R = Rx(a) * Ry(b) * Rz(c).

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/opensim/opensim_function.h"

namespace mmm::opensim {

// A frame fixed to a body: the body itself or a PhysicalOffsetFrame of it
// (chains of offset frames are composed into one offset from the body).
struct FrameRef {
  std::string name;  // frame name as the file names it, path stripped ("femur_r_offset", "tibia_r")
  std::string body;  // body the frame is fixed to ("ground" for the ground frame)
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // frame origin in the body frame (m)
  Eigen::Vector3d orientation = Eigen::Vector3d::Zero();  // X-Y-Z body-fixed angles (rad)

  // Rotation taking frame coordinates to body coordinates (3 by 3).
  [[nodiscard]] Eigen::Matrix3d rotation() const;
  // A point given in this frame, expressed in the body frame (m).
  [[nodiscard]] Eigen::Vector3d to_body(const Eigen::Vector3d& point) const;
};

// X-Y-Z body-fixed rotation matrix Rx(angles.x) * Ry(angles.y) * Rz(angles.z).
Eigen::Matrix3d rotation_xyz(const Eigen::Vector3d& angles);

// A mesh drawn with a body (<attached_geometry><Mesh>; 3.x <DisplayGeometry>).
struct AttachedMesh {
  std::string name;       // component name ("femur_r_geom_1"); the file name in 3.x
  std::string mesh_file;  // as written ("femur_r.vtp"); resolve against the model's Geometry folder
  Eigen::Vector3d scale_factors = Eigen::Vector3d::Ones();  // per-axis scale of the mesh
  std::string frame;  // frame the mesh is attached to (the owning body's name for "..")
};

enum class WrapShape { kSphere, kCylinder, kEllipsoid, kTorus, kOther };

// A wrap surface fixed to a body (<WrapObjectSet>). Fields that do not apply
// to the shape stay 0.
struct WrapObject {
  std::string name;
  std::string type;  // element name: WrapSphere, WrapCylinder, WrapEllipsoid, WrapTorus, ...
  WrapShape shape = WrapShape::kOther;
  std::string body;
  Eigen::Vector3d xyz_body_rotation = Eigen::Vector3d::Zero();  // orientation in the body (rad)
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();        // centre in the body (m)
  std::string quadrant = "all";  // "all", "+x", "-y", ...: side the path may wrap on
  bool active = true;
  double radius = 0.0;                                   // sphere, cylinder (m)
  double length = 0.0;                                   // cylinder (m)
  Eigen::Vector3d dimensions = Eigen::Vector3d::Zero();  // ellipsoid semi-axes (m)
  double inner_radius = 0.0;                             // torus tube radius (m)
  double outer_radius = 0.0;                             // torus centre-line radius (m)
};

struct Body {
  std::string name;
  bool is_ground = false;  // the 4.x <Ground>, or the 3.x body named "ground"
  double mass = 0.0;       // kg
  Eigen::Vector3d mass_center = Eigen::Vector3d::Zero();  // in the body frame (m)
  // Ixx Iyy Izz Ixy Ixz Iyz about the mass centre, body axes (kg m^2).
  std::array<double, 6> inertia{};
  std::vector<AttachedMesh> geometry;
  std::vector<WrapObject> wrap_objects;
};

enum class MotionType { kRotational, kTranslational, kCoupled, kUndefined };

// A generalized coordinate of a joint.
struct Coordinate {
  std::string name;
  std::string joint;              // owning joint
  double default_value = 0.0;     // rad or m
  std::array<double, 2> range{};  // [min, max], rad or m
  bool clamped = false;
  bool locked = false;
  // 3.x: <motion_type>. 4.x: derived the way OpenSim does: a CustomJoint
  // coordinate is rotational (translational) when it drives a rotation
  // (translation) axis through a LinearFunction of slope 1 (possibly inside a
  // MultiplierFunction of scale 1), otherwise coupled (e.g. patella
  // coordinates); other joint types fix it by type (PinJoint rotational,
  // SliderJoint translational, FreeJoint 3 + 3, PlanarJoint 1 + 2, ...).
  MotionType motion_type = MotionType::kUndefined;
};

// One of the 6 axes of a CustomJoint's SpatialTransform: the child moves by
// function(coordinates) about (rotation*) or along (translation*) `axis`,
// expressed in the parent frame. OpenSim applies rotation1..3 then
// translation1..3.
struct TransformAxis {
  std::string name;                      // rotation1..3, translation1..3
  std::vector<std::string> coordinates;  // independent variables (0 or 1 here)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  Function function;  // rad (rotations) or m (translations) of the coordinate value
};

struct Joint {
  std::string name;
  std::string type;  // element name: CustomJoint, WeldJoint, PinJoint, BallJoint, ...
  FrameRef parent;   // socket_parent_frame (3.x: parent_body + location/orientation_in_parent)
  FrameRef child;    // socket_child_frame (3.x: owning body + location/orientation)
  std::vector<Coordinate> coordinates;
  std::vector<TransformAxis> spatial_transform;  // 6 axes for a CustomJoint, else empty
};

// A marker of the model's <MarkerSet>.
struct Marker {
  std::string name;
  FrameRef frame;  // socket_parent_frame ("/bodyset/pelvis" -> body "pelvis"); 3.x <body>
  Eigen::Vector3d location = Eigen::Vector3d::Zero();  // in `frame` (m)
  bool fixed = false;
};

enum class PathPointKind { kPathPoint, kConditional, kMoving };

struct PathPoint {
  std::string name;
  PathPointKind kind = PathPointKind::kPathPoint;
  FrameRef frame;  // socket_parent_frame; 3.x <body>
  // In `frame` (m). For a MovingPathPoint, the value of the location
  // functions at the coordinate's default value.
  Eigen::Vector3d location = Eigen::Vector3d::Zero();
  // ConditionalPathPoint: the point is in the path while the coordinate lies
  // in [range[0], range[1]] (rad or m).
  std::string coordinate;
  std::array<double, 2> range{};
  // MovingPathPoint: location = (x_location(q_x), y_location(q_y), z_location(q_z))
  // with q_* the value of the coordinate named beside it (m).
  Function x_location;
  Function y_location;
  Function z_location;
  std::string x_coordinate;
  std::string y_coordinate;
  std::string z_coordinate;
};

// A <PathWrap> of a GeometryPath.
struct PathWrap {
  std::string name;
  std::string wrap_object;        // name of a WrapObject of some body
  std::string method = "hybrid";  // "hybrid", "midpoint" or "axial"
  std::array<int, 2> range{-1,
                           -1};  // path point indices (1-based) the wrap applies between; -1 all
};

// A force with a GeometryPath (Thelen2003Muscle, Millard2012EquilibriumMuscle,
// PathActuator, Ligament, ...).
struct Muscle {
  std::string name;
  std::string type;           // element name
  bool applies_force = true;  // <appliesForce>; 3.x: not <isDisabled>
  // Muscle parameters (N, m, m, rad); has_muscle_parameters is false and they
  // stay 0 when the force lacks them (a PathActuator, a Ligament).
  bool has_muscle_parameters = false;
  double max_isometric_force = 0.0;
  double optimal_fiber_length = 0.0;
  double tendon_slack_length = 0.0;
  double pennation_angle_at_optimal = 0.0;  // 3.x muscles may call it <pennation_angle>
  std::vector<PathPoint> path_points;       // in path order (origin first)
  std::vector<PathWrap> path_wraps;
};

struct OsimModel {
  std::filesystem::path source;  // the file read (or the name given to parse_osim)
  int version = 0;               // <OpenSimDocument Version>, e.g. 40000
  std::string name;
  std::string credits;
  std::string publications;
  std::string length_units;  // "meters" when present, else empty
  std::string force_units;   // "N" when present, else empty
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, -9.80665, 0.0);  // in ground (m/s^2)
  std::vector<Body> bodies;  // the ground first in 4.x files, then <BodySet> order
  std::vector<Joint> joints;
  std::vector<Marker> markers;
  std::vector<Muscle> muscles;  // <ForceSet> order

  // Lookups by exact name (linear scans); nullptr when absent.
  [[nodiscard]] const Body* find_body(std::string_view body_name) const;
  [[nodiscard]] const Joint* find_joint(std::string_view joint_name) const;
  [[nodiscard]] const Muscle* find_muscle(std::string_view muscle_name) const;
  [[nodiscard]] const Marker* find_marker(std::string_view marker_name) const;
  [[nodiscard]] const Coordinate* find_coordinate(std::string_view coordinate_name) const;
  [[nodiscard]] const WrapObject* find_wrap_object(std::string_view wrap_name) const;
};

// Reads an OpenSim model file.
//
// Accepted: <OpenSimDocument Version="3xxxx" or "4xxxx"> holding one <Model>.
// 4.x layout: <Ground>, <BodySet>, <JointSet> (PhysicalOffsetFrames in the
// joints' <frames>, the bodies' and the model's <components>), <MarkerSet>,
// <ForceSet>, sockets as component paths. 3.x layout: the ground as a body,
// each joint nested in its child <Body><Joint>, <parent_body>,
// <location_in_parent>, <VisibleObject> geometry, <body> of points/markers.
// Forces without a GeometryPath (actuators, springs, contact) are skipped.
//
// Throws IoError(file, "line N: <element> ...: what, expected vs got; hint")
// for: a missing/unreadable file, malformed XML (tinyxml2's line), no
// <OpenSimDocument> or <Model>, a Version older than 3.0 or not an integer,
// a number that is not a finite number, a vector with the wrong number of
// values, a bad boolean, a function element of an unknown type or a
// SimmSpline/PiecewiseLinearFunction whose x and y counts differ or whose x
// does not strictly increase, a frame/body/coordinate/wrap object that is
// referenced but not defined, a cycle of offset frames, and duplicate names
// of bodies, joints, coordinates or muscles.
OsimModel read_osim(const std::filesystem::path& file);

// Same, from the XML text in memory; `name_for_messages` is the path put in
// error messages and in OsimModel::source.
OsimModel parse_osim(std::string_view xml, const std::filesystem::path& name_for_messages);

}  // namespace mmm::opensim

#pragma once
// The musculoskeletal atlas: the generic model every study starts from, and
// (scaled) the patient's own. Everything is expressed in one frame, the atlas
// frame, in millimetres, in the rest pose the atlas was built in (for the
// default atlas: the Visible Human Female frame, x toward the subject's
// right, y anterior, z superior, standing). Elements refer to each other by
// name; the manifest (schemas/atlas.schema.yaml, atlas_io.h) stores it as
// YAML beside a folder of meshes.
//
//   regions (pelvis, right thigh, ...) -> bones and muscles
//   bones: rigid bodies, surface meshes at several resolutions, rest frame,
//          the joint that attaches them to their parent
//   joints: OpenSim-style (a parent and a child frame, coordinates, and for
//          custom joints six transform axes whose functions couple
//          translations to rotations, as gait2392's knee)
//   muscles: surface meshes, action lines (origin -> via points -> insertion,
//          each point on a bone), attachment areas on the bones, wrap
//          obstacles, default fibre architecture
//   landmarks: named points on bones; markers: the motion-capture marker set
//   tags on every element, for lookups by anatomy, side or group

#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/opensim/opensim_function.h"

namespace mmm::atlas {

// One resolution of an element's surface: "full" is the source resolution,
// "lod1", "lod2", ... coarser ones.
struct MeshLevel {
  std::string level;  // "full", "lod1", ...
  std::string file;   // relative to the atlas folder, e.g. "meshes/femur_r/full.ply"
  int faces = 0;
};

struct Bone {
  std::string name;  // e.g. "femur_r"
  std::vector<std::string> tags;
  std::vector<MeshLevel> meshes;  // "full" first
  // Rest pose of the bone's local frame: local -> atlas (mm). Motion moves
  // this frame; points on the bone are stored in atlas coordinates at rest.
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  std::string parent_joint;  // empty for the root bone (the pelvis)
};

enum class JointType { kWeld, kPin, kBall, kCustom };
std::string_view joint_type_name(JointType type);
std::optional<JointType> joint_type_from_name(std::string_view name);

enum class CoordinateKind { kRotational, kTranslational, kCoupled };

struct Coordinate {
  std::string name;  // OpenSim name, e.g. "knee_angle_r"
  CoordinateKind kind = CoordinateKind::kRotational;
  std::array<double, 2> range{};  // rad or mm
  double rest_value = 0.0;        // value in the atlas rest pose (rad or mm)
  double default_value = 0.0;     // OpenSim default (rad or mm)
};

// One axis of a custom joint (OpenSim TransformAxis): the child moves by
// function(coordinate) about (rotations) or along (translations) `axis`,
// expressed in the joint's parent frame. Rotations 1..3 apply first, then
// translations 1..3.
struct TransformAxis {
  bool rotation = true;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  std::string coordinate;      // empty: constant function
  opensim::Function function;  // rad or mm of the coordinate value
};

struct Joint {
  std::string name;  // e.g. "knee_r"
  JointType type = JointType::kWeld;
  std::string parent;  // bone
  std::string child;   // bone
  // Joint frames at rest, in atlas coordinates: the frame fixed to the parent
  // and the frame fixed to the child. child_pose = parent_pose *
  // parent_offset * motion(q) * child_offset^-1 with the offsets taken in the
  // bones' local frames (see joint_kinematics.h).
  Eigen::Isometry3d parent_frame = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d child_frame = Eigen::Isometry3d::Identity();
  std::vector<Coordinate> coordinates;
  std::vector<TransformAxis> axes;  // kCustom: 6 (rotation1..3, translation1..3)
};

// kFollowsLine: a point added by the atlas build to keep the line inside its
// muscle; it keeps its rest place relative to the segment between the
// nearest other active points before and after it (fraction along it,
// offset turned with it), so it bends the line without changing how the
// line's length depends on the joints (wrapping/action_line_path.h).
enum class PathPointKind { kFixed, kConditional, kMoving, kFollowsLine };

struct PathPoint {
  std::string name;
  std::string bone;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // atlas, rest pose (mm)
  PathPointKind kind = PathPointKind::kFixed;
  // kConditional: active while `coordinate` is in `range`.
  std::string coordinate;
  std::array<double, 2> range{};
  // kMoving: position in the bone's local frame is (x(q_x), y(q_y), z(q_z)) (mm).
  std::array<std::string, 3> moving_coordinates;
  std::array<opensim::Function, 3> moving_functions;
};

// Origin -> via points -> insertion; several per muscle when the muscle has
// several heads or bundles (e.g. gluteus medius 1, 2, 3).
struct ActionLine {
  std::string name;  // e.g. "glut_med1_r" (the gait2392 muscle it comes from)
  std::vector<PathPoint> points;
  std::vector<std::string> wrap_obstacles;  // names, in the order they apply
};

// Where a muscle meets a bone: a patch of the bone's full-resolution surface.
struct AttachmentArea {
  std::string bone;
  std::vector<int> faces;  // face indices into the bone's "full" mesh
  double area_mm2 = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // atlas (mm)
};

enum class WrapShape { kSphere, kCylinder, kEllipsoid };
std::string_view wrap_shape_name(WrapShape shape);
std::optional<WrapShape> wrap_shape_from_name(std::string_view name);

// An analytic surface fixed to a bone that action lines wrap around.
struct WrapObstacle {
  std::string name;
  WrapShape shape = WrapShape::kSphere;
  std::string bone;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // shape frame -> atlas (mm)
  // Sphere: radii.x; cylinder: radius radii.x, length radii.z; ellipsoid:
  // the three semi-axes (mm).
  Eigen::Vector3d radii = Eigen::Vector3d::Zero();
  std::string quadrant = "all";  // side the path may wrap on ("+x", "-y", ...)
};

enum class FibreArchitecture { kParallel, kPennate, kFanned, kCurved };
std::string_view fibre_architecture_name(FibreArchitecture architecture);
std::optional<FibreArchitecture> fibre_architecture_from_name(std::string_view name);

struct Muscle {
  std::string name;  // e.g. "gluteus_medius_r"
  std::vector<std::string> tags;
  std::vector<MeshLevel> meshes;  // "full" first
  std::vector<ActionLine> action_lines;
  std::vector<AttachmentArea> origins;
  std::vector<AttachmentArea> insertions;
  std::vector<WrapObstacle> wrap_obstacles;
  FibreArchitecture architecture = FibreArchitecture::kParallel;
  // From the OpenSim model the action lines come from (0 when unknown).
  double max_isometric_force_n = 0.0;
  double optimal_fibre_length_mm = 0.0;
  double tendon_slack_length_mm = 0.0;
  double pennation_angle_rad = 0.0;
};

// A passive structure carried by the bones: a cartilage covers one bone (the
// joint's contact surface), a ligament runs from one bone to another. Both
// are scaled with their bones and moved by them (structure_carriage.h); the
// muscles and action lines do not depend on them.
enum class StructureKind { kCartilage, kLigament };
std::string_view structure_kind_name(StructureKind kind);
std::optional<StructureKind> structure_kind_from_name(std::string_view name);

struct Structure {
  std::string name;  // e.g. "femur_distal_cartilage_r"
  StructureKind kind = StructureKind::kCartilage;
  std::vector<std::string> tags;
  std::vector<MeshLevel> meshes;  // "full" first
  // Cartilage: the bone it covers. Ligament: the bones it joins, [from, to].
  std::vector<std::string> bones;
};

struct Landmark {
  std::string name;  // e.g. "femoral_head_centre_r"
  std::string bone;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // atlas, rest pose (mm)
  std::vector<std::string> tags;
  std::string description;
};

// A motion-capture marker of the atlas's marker set (gait2392 names).
struct Marker {
  std::string name;  // e.g. "R.ASIS"
  std::string bone;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // atlas, rest pose (mm)
  bool fixed = false;                                  // OpenSim: not moved by marker placement
};

struct Region {
  std::string name;  // e.g. "right_thigh"
  std::vector<std::string> tags;
  std::vector<std::string> bones;
  std::vector<std::string> muscles;
  std::vector<std::string> structures;
};

struct Atlas {
  std::string name;
  std::string description;
  std::string frame_description;  // axes and origin, e.g. "VHF: x right, y anterior, z superior"
  std::vector<std::string> provenance;  // one line per source / build step
  std::vector<Region> regions;
  std::vector<Bone> bones;
  std::vector<Joint> joints;
  std::vector<Muscle> muscles;
  std::vector<Structure> structures;
  std::vector<Landmark> landmarks;
  std::vector<Marker> markers;

  // Lookups by exact name; nullptr when absent.
  [[nodiscard]] const Bone* find_bone(std::string_view element) const;
  [[nodiscard]] const Joint* find_joint(std::string_view element) const;
  [[nodiscard]] const Muscle* find_muscle(std::string_view element) const;
  [[nodiscard]] const Landmark* find_landmark(std::string_view element) const;
  [[nodiscard]] const Marker* find_marker(std::string_view element) const;
  [[nodiscard]] const Region* find_region(std::string_view element) const;
  [[nodiscard]] const Structure* find_structure(std::string_view element) const;
  [[nodiscard]] Bone* find_bone(std::string_view element);
  [[nodiscard]] Muscle* find_muscle(std::string_view element);

  // Names of every bone, muscle, structure, landmark and region carrying `tag`.
  [[nodiscard]] std::vector<std::string> find_by_tag(std::string_view tag) const;
};

// The landmarks every atlas must define (the landmark station asks for the
// first three).
inline constexpr std::array<std::string_view, 3> kRequiredLandmarks = {
    "femoral_head_centre_r", "patella_centre_r", "ankle_centre_r"};

}  // namespace mmm::atlas

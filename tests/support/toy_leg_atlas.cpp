#include "tests/support/toy_leg_atlas.h"

#include <string>
#include <vector>

#include "core/atlas/atlas_meshes.h"
#include "core/mesh/primitives.h"

namespace mmm::test {

using Eigen::Vector3d;

mesh::IndexedMesh ellipsoid(const Vector3d& centre, const Vector3d& radii, int subdivisions) {
  mesh::IndexedMesh surface = mesh::make_icosphere(subdivisions, 1.0);
  for (Eigen::Index i = 0; i < surface.V.rows(); ++i) {
    surface.V.row(i) = (centre + radii.cwiseProduct(surface.V.row(i).transpose())).transpose();
  }
  return surface;
}

ToyLeg toy_leg() {
  ToyLeg leg;
  atlas::Atlas& a = leg.atlas;
  a.name = "toy_leg";
  const Vector3d hip(80, 0, -50), knee(85, 10, -450), ankle(70, 0, -830);
  const auto add_bone = [&](const std::string& name, const Vector3d& centre,
                            const Vector3d& radii) {
    atlas::Bone bone;
    bone.name = name;
    bone.frame.translation() = centre;
    bone.meshes = {{"full", "meshes/" + name + "/full.ply", 0},
                   {"lod1", "meshes/" + name + "/lod1.ply", 0}};
    a.bones.push_back(bone);
    leg.meshes[name]["full"] = ellipsoid(centre, radii, 3);
    leg.meshes[name]["lod1"] = ellipsoid(centre, radii, 2);
  };
  add_bone("pelvis", Vector3d(45, 0, 0), Vector3d(120, 40, 45));
  add_bone("femur_r", 0.5 * (hip + knee), Vector3d(18, 18, 205));
  add_bone("tibia_r", 0.5 * (knee + ankle), Vector3d(16, 16, 195));
  add_bone("patella_r", Vector3d(88, 45, -440), Vector3d(12, 8, 14));
  add_bone("talus_r", ankle, Vector3d(15, 20, 12));
  const auto joint = [&](const std::string& name, const std::string& parent,
                         const std::string& child, const Vector3d& centre, atlas::JointType type,
                         const std::vector<std::string>& coordinates) {
    atlas::Joint j;
    j.name = name;
    j.type = type;
    j.parent = parent;
    j.child = child;
    j.parent_frame.translation() = centre;
    j.child_frame.translation() = centre;
    for (const std::string& coordinate : coordinates) {
      atlas::Coordinate c;
      c.name = coordinate;
      c.range = {-2.0, 2.0};
      j.coordinates.push_back(c);
    }
    for (atlas::Bone& bone : a.bones) {
      if (bone.name == child) bone.parent_joint = name;
    }
    return j;
  };
  a.joints = {
      joint("hip_r", "pelvis", "femur_r", hip, atlas::JointType::kBall,
            {"hip_flexion_r", "hip_adduction_r", "hip_rotation_r"}),
      joint("knee_r", "femur_r", "tibia_r", knee, atlas::JointType::kPin, {"knee_angle_r"}),
      joint("patella_weld", "tibia_r", "patella_r", Vector3d(88, 45, -440), atlas::JointType::kWeld,
            {}),
      joint("ankle_r", "tibia_r", "talus_r", ankle, atlas::JointType::kPin, {"ankle_angle_r"})};
  const auto landmark = [](const std::string& name, const std::string& bone, const Vector3d& p) {
    atlas::Landmark l;
    l.name = name;
    l.bone = bone;
    l.position = p;
    return l;
  };
  a.landmarks = {landmark("femoral_head_centre_r", "femur_r", Vector3d(81, 0.5, -49)),
                 landmark("patella_centre_r", "patella_r", Vector3d(88, 45, -440)),
                 landmark("ankle_centre_r", "tibia_r", Vector3d(71, 1, -828)),
                 landmark("lateral_epicondyle_r", "femur_r", Vector3d(103, 10, -440)),
                 landmark("asis_r", "pelvis", Vector3d(150, 30, 20)),
                 landmark("asis_l", "pelvis", Vector3d(-60, 30, 20))};
  atlas::Marker marker;
  marker.name = "R.Thigh";
  marker.bone = "femur_r";
  marker.position = Vector3d(125, 0, -300);
  a.markers = {marker};
  atlas::Muscle muscle;
  muscle.name = "vastus_r";
  muscle.meshes = {{"full", "meshes/vastus_r/full.ply", 0},
                   {"lod1", "meshes/vastus_r/lod1.ply", 0}};
  leg.meshes["vastus_r"]["full"] = ellipsoid(Vector3d(108.5, 5, -250), Vector3d(10, 10, 150), 3);
  leg.meshes["vastus_r"]["lod1"] = ellipsoid(Vector3d(108.5, 5, -250), Vector3d(10, 10, 150), 2);
  atlas::ActionLine line;
  line.name = "vastus_r";
  const auto point = [](const std::string& name, const std::string& bone, const Vector3d& p) {
    atlas::PathPoint path_point;
    path_point.name = name;
    path_point.bone = bone;
    path_point.position = p;
    return path_point;
  };
  line.points = {point("origin", "femur_r", Vector3d(100, 5, -150)),
                 point("insertion", "tibia_r", Vector3d(90, 30, -480))};
  muscle.action_lines = {line};
  atlas::AttachmentArea origin;
  origin.bone = "femur_r";
  origin.faces = {0, 1, 2};
  origin.centroid = Vector3d(98, 5, -150);
  muscle.origins = {origin};
  atlas::WrapObstacle wrap;
  wrap.name = "knee_wrap";
  wrap.bone = "femur_r";
  wrap.pose.translation() = Vector3d(85, 10, -430);
  wrap.radii = Vector3d(20, 0, 0);
  muscle.wrap_obstacles = {wrap};
  a.muscles = {muscle};
  for (atlas::Bone& bone : a.bones) {
    for (atlas::MeshLevel& level : bone.meshes) {
      level.faces = static_cast<int>(leg.meshes.at(bone.name).at(level.level).F.rows());
    }
  }
  for (atlas::MeshLevel& level : a.muscles[0].meshes) {
    level.faces = static_cast<int>(leg.meshes.at(a.muscles[0].name).at(level.level).F.rows());
  }
  // A cartilage on the distal femur and a ligament from the femur to the tibia.
  const auto add_structure = [&](const std::string& name, atlas::StructureKind kind,
                                 std::vector<std::string> bones, const Vector3d& centre,
                                 const Vector3d& radii) {
    atlas::Structure structure;
    structure.name = name;
    structure.kind = kind;
    structure.bones = std::move(bones);
    leg.meshes[name]["full"] = ellipsoid(centre, radii, 3);
    leg.meshes[name]["lod1"] = ellipsoid(centre, radii, 2);
    for (const char* level : {"full", "lod1"}) {
      structure.meshes.push_back({level, "meshes/" + name + "/" + level + ".ply",
                                  static_cast<int>(leg.meshes[name][level].F.rows())});
    }
    a.structures.push_back(structure);
  };
  add_structure("femur_cartilage_r", atlas::StructureKind::kCartilage, {"femur_r"},
                Vector3d(82.5, 5, -452), Vector3d(14, 14, 5));
  add_structure("knee_ligament_r", atlas::StructureKind::kLigament, {"femur_r", "tibia_r"},
                Vector3d(87, 5, -450), Vector3d(3, 3, 25));
  return leg;
}

void write_toy_leg(const std::filesystem::path& dir) {
  const ToyLeg leg = toy_leg();
  atlas::write_atlas_with_meshes(leg.atlas, leg.meshes, dir);
}

}  // namespace mmm::test

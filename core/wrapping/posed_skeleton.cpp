#include "core/wrapping/posed_skeleton.h"

#include <memory>
#include <utility>

#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"

namespace mmm::wrapping {

using Eigen::Isometry3d;
using Eigen::VectorXd;

const atlas::MeshLevel& full_level(const std::vector<atlas::MeshLevel>& levels,
                                   const std::string& element) {
  for (const atlas::MeshLevel& level : levels) {
    if (level.level == "full") return level;
  }
  if (levels.empty()) throw InvalidInputError("muscle wrapping: '" + element + "' has no mesh");
  return levels.front();
}

// Every skeleton coordinate at its atlas rest value.
VectorXd rest_coordinates(const atlas::Atlas& atlas, const motion::Skeleton& skeleton) {
  VectorXd q = skeleton.default_coordinates();
  for (const atlas::Joint& joint : atlas.joints) {
    for (const atlas::Coordinate& coordinate : joint.coordinates) {
      if (const auto index = skeleton.coordinate_index(coordinate.name))
        q[*index] = coordinate.rest_value;
    }
  }
  return q;
}

// The motion's frames as coordinate vectors of `skeleton` (by name).
std::vector<VectorXd> frame_coordinates(const motion::FusedMotion& motion,
                                        const motion::Skeleton& skeleton, const VectorXd& rest) {
  std::vector<std::pair<int, int>> columns;  // skeleton index, motion column
  for (int c = 0; c < skeleton.num_coordinates(); ++c) {
    if (const auto column =
            motion.coordinate_index(skeleton.coordinates[static_cast<std::size_t>(c)].name)) {
      columns.emplace_back(c, *column);
    }
  }
  if (columns.empty()) {
    throw InvalidInputError(
        "muscle wrapping: the motion has none of the atlas skeleton's coordinates; hint: fuse the "
        "motion on this atlas (fuse_motion with the atlas input)");
  }
  std::vector<VectorXd> frames;
  for (Eigen::Index f = 0; f < motion.num_frames(); ++f) {
    VectorXd q = rest;
    for (const auto& [index, column] : columns) q[index] = motion.coordinates(f, column);
    frames.push_back(std::move(q));
  }
  return frames;
}

PosedBones load_bones(const atlas::Atlas& atlas, const std::filesystem::path& dir,
                      const motion::Skeleton& skeleton) {
  PosedBones bones;
  for (const atlas::Bone& bone : atlas.bones) {
    const auto body = skeleton.body_index(bone.name);
    if (!body || bone.meshes.empty()) continue;
    const mesh::IndexedMesh surface =
        mesh::read_mesh(dir / full_level(bone.meshes, bone.name).file);
    bones.index[bone.name] = static_cast<int>(bones.names.size());
    bones.names.push_back(bone.name);
    bones.bodies.push_back(*body);
    bones.surfaces.push_back({bone.name, std::make_shared<const mesh::SignedDistance>(surface)});
  }
  return bones;
}

std::vector<Isometry3d> bone_poses(const motion::SkeletonPose& pose, const PosedBones& bones) {
  std::vector<Isometry3d> poses;
  poses.reserve(bones.bodies.size());
  for (const int body : bones.bodies) poses.push_back(pose.body_pose(body));
  return poses;
}

int bone_index(const PosedBones& bones, const std::string& bone, const std::string& what) {
  const auto found = bones.index.find(bone);
  if (found == bones.index.end()) {
    throw InvalidInputError("muscle wrapping: " + what + " is on bone '" + bone +
                            "', which has no mesh or is not in the skeleton");
  }
  return found->second;
}

std::vector<const atlas::Muscle*> selected_muscles(const atlas::Atlas& atlas,
                                                   const std::vector<std::string>& names) {
  std::vector<const atlas::Muscle*> muscles;
  if (names.empty()) {
    for (const atlas::Muscle& muscle : atlas.muscles) muscles.push_back(&muscle);
    return muscles;
  }
  for (const std::string& name : names) {
    const atlas::Muscle* muscle = atlas.find_muscle(name);
    if (muscle == nullptr)
      throw InvalidInputError("muscle wrapping: the atlas has no muscle '" + name + "'");
    muscles.push_back(muscle);
  }
  return muscles;
}

}  // namespace mmm::wrapping

#include "core/atlas/kinematic_chain.h"

#include <set>

#include "core/errors.h"

namespace mmm::atlas {

const Joint* joint_to(const Atlas& atlas, std::string_view bone) {
  for (const Joint& joint : atlas.joints) {
    if (joint.child == bone) return &joint;
  }
  return nullptr;
}

std::vector<const Bone*> chain_order(const Atlas& atlas, std::string_view what) {
  const Bone* root = nullptr;
  for (const Bone& bone : atlas.bones) {
    if (joint_to(atlas, bone.name) == nullptr) {
      root = &bone;
      break;
    }
  }
  if (root == nullptr) {
    throw InvalidInputError(std::string(what) +
                            ": the atlas has no root bone (every bone hangs from a joint)");
  }
  std::vector<const Bone*> order{root};
  std::set<std::string> placed{root->name};
  for (bool progress = true; progress;) {
    progress = false;
    for (const Bone& bone : atlas.bones) {
      if (placed.contains(bone.name)) continue;
      const Joint* joint = joint_to(atlas, bone.name);
      if (joint == nullptr || placed.contains(joint->parent)) {
        order.push_back(&bone);
        placed.insert(bone.name);
        progress = true;
      }
    }
  }
  if (order.size() != atlas.bones.size()) {
    throw InvalidInputError(std::string(what) + ": some bones are not connected to the root '" +
                            root->name + "' by joints");
  }
  return order;
}

std::string moving_with(const Atlas& atlas, std::string bone) {
  for (std::size_t guard = 0; guard <= atlas.joints.size(); ++guard) {
    const Joint* joint = joint_to(atlas, bone);
    if (joint == nullptr || joint->type != JointType::kWeld) return bone;
    bone = joint->parent;
  }
  return bone;
}

std::vector<std::string> welded_together(const Atlas& atlas, std::string_view bone) {
  const std::string segment = moving_with(atlas, std::string(bone));
  std::vector<std::string> bones;
  for (const Bone& other : atlas.bones) {
    if (other.name == bone || moving_with(atlas, other.name) == segment) {
      bones.push_back(other.name);
    }
  }
  if (bones.empty()) bones.emplace_back(bone);  // not an atlas bone: itself
  return bones;
}

std::optional<Eigen::Vector3d> distal_joint_centre(const Atlas& atlas, std::string_view bone) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (const Joint& joint : atlas.joints) {
    if (joint.parent == bone && joint.type != JointType::kWeld) {
      sum += joint.child_frame.translation();
      ++count;
    }
  }
  if (count == 0) return std::nullopt;
  return sum / count;
}

}  // namespace mmm::atlas

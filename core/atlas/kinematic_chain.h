#pragma once
// Walking an atlas's kinematic chain: the joint that moves a bone, the bones
// in parent-before-child order, the bone a welded bone moves with, and the
// centre of a bone's distal joints (for its long axis). Shared by the
// synthetic patients' deformation and atlas scaling.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/atlas/atlas.h"

namespace mmm::atlas {

// The joint whose child is `bone`, or nullptr (the root).
const Joint* joint_to(const Atlas& atlas, std::string_view bone);

// Every bone, each after its parent; the root (the first bone no joint
// moves) first. Throws InvalidInputError, its message starting with
// `what`, when no bone is a root or some bone is not connected to it.
std::vector<const Bone*> chain_order(const Atlas& atlas, std::string_view what);

// The bone whose placement `bone` follows: itself, or the bone at the end
// of its chain of weld joints.
std::string moving_with(const Atlas& atlas, std::string bone);

// Mean of the centres (child frames at rest) of the non-weld joints that
// hang from `bone`; nullopt when none does. gait2392 puts the knee's parent
// frame at the femur's origin and moves the knee by coupled translations,
// so the child frames, not the parent frames, are where the joints are.
std::optional<Eigen::Vector3d> distal_joint_centre(const Atlas& atlas, std::string_view bone);

}  // namespace mmm::atlas

#pragma once
// Walking an atlas's kinematic chain: the joint that moves a bone, the bones
// in parent-before-child order, the bone a welded bone moves with, the bones
// welded into one segment, and the centre of a bone's distal joints (for its
// long axis). Shared by the atlas build, the synthetic patients' deformation
// and atlas scaling.

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

// The bones that move as one with `bone` (the same moving_with): `bone`
// itself and every bone joined to it through weld joints, in atlas order.
// A rigid segment split into several bones (the pelvis: right hip bone,
// mirrored left hip bone, sacrum, coccyx) is found whole from any of them.
std::vector<std::string> welded_together(const Atlas& atlas, std::string_view bone);

// Mean of the centres (child frames at rest) of the non-weld joints that
// hang from `bone`; nullopt when none does. gait2392 puts the knee's parent
// frame at the femur's origin and moves the knee by coupled translations,
// so the child frames, not the parent frames, are where the joints are.
std::optional<Eigen::Vector3d> distal_joint_centre(const Atlas& atlas, std::string_view bone);

}  // namespace mmm::atlas

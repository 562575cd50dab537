#pragma once
// The atlas's skeleton posed by a fused motion, for the wrapping pathways:
// the rest coordinates, the motion's frames as coordinate vectors, the bones
// that have a mesh and a body (their surfaces ready for distance queries)
// and their poses (atlas rest frame -> frame).

#include <Eigen/Geometry>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/skeleton.h"
#include "core/wrapping/bone_contacts.h"

namespace mmm::wrapping {

// The level named "full", else the first. Throws InvalidInputError naming
// `element` when there is none.
const atlas::MeshLevel& full_level(const std::vector<atlas::MeshLevel>& levels,
                                   const std::string& element);

// Every skeleton coordinate at its atlas rest value.
Eigen::VectorXd rest_coordinates(const atlas::Atlas& atlas, const motion::Skeleton& skeleton);

// The motion's frames as coordinate vectors of `skeleton` (matched by name;
// the others keep `rest`). Throws InvalidInputError when the motion has none
// of the skeleton's coordinates.
std::vector<Eigen::VectorXd> frame_coordinates(const motion::FusedMotion& motion,
                                               const motion::Skeleton& skeleton,
                                               const Eigen::VectorXd& rest);

struct PosedBones {
  std::vector<std::string> names;
  std::vector<int> bodies;  // skeleton body per bone
  std::vector<PosableBone> surfaces;
  std::map<std::string, int> index;
};

// The atlas bones with a mesh and a body in `skeleton` (full level).
PosedBones load_bones(const atlas::Atlas& atlas, const std::filesystem::path& dir,
                      const motion::Skeleton& skeleton);

std::vector<Eigen::Isometry3d> bone_poses(const motion::SkeletonPose& pose,
                                          const PosedBones& bones);

// Index of `bone` in `bones`. Throws InvalidInputError naming `what`.
int bone_index(const PosedBones& bones, const std::string& bone, const std::string& what);

// The named muscles (all when `names` is empty), in the order given.
// Throws InvalidInputError for an unknown name.
std::vector<const atlas::Muscle*> selected_muscles(const atlas::Atlas& atlas,
                                                   const std::vector<std::string>& names);

}  // namespace mmm::wrapping

#pragma once
// How a cartilage or ligament (atlas.h, Structure) follows its bones, both
// through scaling and through motion. A cartilage is carried by the bone it
// covers, rigidly. A ligament vertex is carried by the two bones it joins in
// proportion to how near it lies to each: with d_a, d_b its distances to the
// two bone surfaces (0 inside), t = d_a / (d_a + d_b) and the second bone's
// weight w_b = 3t^2 - 2t^3 (smooth, 0 on the first bone, 1 on the second);
// its moved position is the blend of the two bones' maps of it. At its
// attachments a ligament moves exactly with the bone; between them it
// stretches and turns smoothly (a linear blend of rigid maps: at large
// relative rotations the middle of the ligament thins, as in skinning).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/mesh/signed_distance.h"

namespace mmm::atlas {

// Per vertex (row) the weight of each of the structure's bones (columns, in
// `structure.bones` order; rows sum to 1). `bones` are the signed distances
// of those bones' surfaces at rest, in the same order. Throws
// InvalidInputError when the counts disagree.
Eigen::MatrixXd carriage_weights(const Structure& structure, const Eigen::MatrixX3d& rest,
                                 const std::vector<const mesh::SignedDistance*>& bones);

// The rest vertices moved by the bones' poses (rest -> moved, one per
// column of `weights`): sum_b w_b (pose_b * v).
Eigen::MatrixX3d carried(const Eigen::MatrixX3d& rest, const Eigen::MatrixXd& weights,
                         const std::vector<Eigen::Isometry3d>& poses);

// A structure at one level of detail, weighed on its bones, ready to be
// moved frame by frame with `carried`.
struct CarriedStructure {
  std::string name;
  mesh::IndexedMesh rest;          // atlas rest frame (mm)
  std::vector<std::string> bones;  // the columns of `weights`
  Eigen::MatrixXd weights;
};

// `structure`'s surface moved by its bones: `pose_of` gives a bone's pose
// (rest -> moved), or nullopt for a bone that does not move; nullopt when
// one of the structure's bones does not (it is then not drawn).
std::optional<mesh::IndexedMesh> carried_surface(
    const CarriedStructure& structure,
    const std::function<std::optional<Eigen::Isometry3d>(const std::string& bone)>& pose_of);

// Every structure of the atlas in `dir` at `level` (the finest level it has
// when it lacks that one), weighed on its bones' surfaces at the same level.
// Throws IoError naming a mesh that cannot be read.
std::vector<CarriedStructure> carried_structures(const Atlas& atlas,
                                                 const std::filesystem::path& dir,
                                                 const std::string& level);

}  // namespace mmm::atlas

#include "core/atlas/structure_carriage.h"

#include <algorithm>
#include <map>
#include <memory>

#include "core/atlas/atlas_io.h"

#include "core/errors.h"

namespace mmm::atlas {

Eigen::MatrixXd carriage_weights(const Structure& structure, const Eigen::MatrixX3d& rest,
                                 const std::vector<const mesh::SignedDistance*>& bones) {
  if (bones.size() != structure.bones.size() || bones.empty()) {
    throw InvalidInputError("structure " + structure.name + ": " +
                            std::to_string(structure.bones.size()) + " bone(s) named, " +
                            std::to_string(bones.size()) + " surface(s) given");
  }
  Eigen::MatrixXd weights =
      Eigen::MatrixXd::Zero(rest.rows(), static_cast<Eigen::Index>(bones.size()));
  if (bones.size() == 1) {
    weights.setOnes();
    return weights;
  }
  const Eigen::VectorXd to_first = bones[0]->at(rest).cwiseMax(0.0);
  const Eigen::VectorXd to_second = bones[1]->at(rest).cwiseMax(0.0);
  for (Eigen::Index i = 0; i < rest.rows(); ++i) {
    const double total = to_first(i) + to_second(i);
    const double t = total > 0 ? to_first(i) / total : 0.5;  // inside both: halfway
    const double second = t * t * (3.0 - 2.0 * t);
    weights(i, 0) = 1.0 - second;
    weights(i, 1) = second;
  }
  return weights;
}

Eigen::MatrixX3d carried(const Eigen::MatrixX3d& rest, const Eigen::MatrixXd& weights,
                         const std::vector<Eigen::Isometry3d>& poses) {
  if (weights.rows() != rest.rows() || static_cast<std::size_t>(weights.cols()) != poses.size()) {
    throw InvalidInputError("carried: " + std::to_string(weights.cols()) +
                            " weight column(s) for " + std::to_string(poses.size()) + " pose(s)");
  }
  Eigen::MatrixX3d moved = Eigen::MatrixX3d::Zero(rest.rows(), 3);
  for (std::size_t b = 0; b < poses.size(); ++b) {
    const Eigen::Matrix3d& linear = poses[b].linear();
    const Eigen::RowVector3d offset = poses[b].translation().transpose();
    const Eigen::MatrixX3d mapped = (rest * linear.transpose()).rowwise() + offset;
    moved.array() += mapped.array().colwise() * weights.col(static_cast<Eigen::Index>(b)).array();
  }
  return moved;
}

namespace {

std::string level_or_finest(const std::vector<MeshLevel>& levels, const std::string& level) {
  const bool has =
      std::ranges::any_of(levels, [&](const MeshLevel& m) { return m.level == level; });
  return has || levels.empty() ? level : levels.front().level;
}

}  // namespace

std::optional<mesh::IndexedMesh> carried_surface(
    const CarriedStructure& structure,
    const std::function<std::optional<Eigen::Isometry3d>(const std::string& bone)>& pose_of) {
  std::vector<Eigen::Isometry3d> carriers;
  for (const std::string& bone : structure.bones) {
    const std::optional<Eigen::Isometry3d> pose = pose_of(bone);
    if (!pose) return std::nullopt;
    carriers.push_back(*pose);
  }
  mesh::IndexedMesh moved = structure.rest;
  moved.V = carried(structure.rest.V, structure.weights, carriers);
  return moved;
}

std::vector<CarriedStructure> carried_structures(const Atlas& atlas,
                                                 const std::filesystem::path& dir,
                                                 const std::string& level) {
  std::vector<CarriedStructure> result;
  std::map<std::string, std::unique_ptr<mesh::SignedDistance>> bones;
  for (const Structure& structure : atlas.structures) {
    CarriedStructure carried_one;
    carried_one.name = structure.name;
    carried_one.bones = structure.bones;
    carried_one.rest = load_mesh(dir, structure.meshes, level_or_finest(structure.meshes, level));
    std::vector<const mesh::SignedDistance*> distances;
    for (const std::string& name : structure.bones) {
      if (!bones.contains(name)) {
        const Bone* bone = atlas.find_bone(name);
        if (bone == nullptr) {
          throw InvalidInputError("structure " + structure.name + ": unknown bone " + name);
        }
        bones[name] = std::make_unique<mesh::SignedDistance>(
            load_mesh(dir, bone->meshes, level_or_finest(bone->meshes, level)));
      }
      distances.push_back(bones.at(name).get());
    }
    carried_one.weights = carriage_weights(structure, carried_one.rest.V, distances);
    result.push_back(std::move(carried_one));
  }
  return result;
}

}  // namespace mmm::atlas

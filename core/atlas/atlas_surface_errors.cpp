#include "core/atlas/atlas_surface_errors.h"

#include <cstddef>

#include "core/atlas/atlas_io.h"
#include "core/errors.h"
#include "core/parallel_for.h"

namespace mmm::atlas {
namespace {

struct Pair {
  std::string element;
  std::string kind;
  const std::vector<MeshLevel>* estimate = nullptr;
  const std::vector<MeshLevel>* truth = nullptr;
};

}  // namespace

std::vector<ElementSurfaceError> atlas_surface_errors(const std::filesystem::path& estimate_dir,
                                                      const std::filesystem::path& truth_dir,
                                                      const std::string& level, int threads) {
  const Atlas estimate = read_atlas(estimate_dir);
  const Atlas truth = read_atlas(truth_dir);
  const auto missing = [&](const std::string& kind, const std::string& name) {
    return InvalidInputError(
        "the true atlas " + truth_dir.string() + " has no " + kind + " '" + name +
        "'; hint: the truth must come from the same generic atlas as the estimate "
        "(mmm patient synth --atlas GENERIC)");
  };
  std::vector<Pair> pairs;
  for (const Bone& bone : estimate.bones) {
    const Bone* other = truth.find_bone(bone.name);
    if (other == nullptr) throw missing("bone", bone.name);
    pairs.push_back({bone.name, "bone", &bone.meshes, &other->meshes});
  }
  for (const Muscle& muscle : estimate.muscles) {
    const Muscle* other = truth.find_muscle(muscle.name);
    if (other == nullptr) throw missing("muscle", muscle.name);
    pairs.push_back({muscle.name, "muscle", &muscle.meshes, &other->meshes});
  }
  std::vector<ElementSurfaceError> errors(pairs.size());
  parallel_for(pairs.size(), threads, [&](std::size_t i) {
    const Pair& pair = pairs[i];
    errors[i] = {pair.element, pair.kind,
                 mesh::surface_distance(load_mesh(estimate_dir, *pair.estimate, level),
                                        load_mesh(truth_dir, *pair.truth, level))};
  });
  return errors;
}

}  // namespace mmm::atlas

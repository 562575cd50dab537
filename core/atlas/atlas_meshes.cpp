#include "core/atlas/atlas_meshes.h"

#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/parallel_for.h"

namespace mmm::atlas {
namespace {

struct MeshJob {
  std::string element;
  const MeshLevel* level;
};

std::vector<MeshJob> mesh_jobs(const Atlas& atlas) {
  std::vector<MeshJob> jobs;
  for (const Bone& bone : atlas.bones) {
    for (const MeshLevel& level : bone.meshes) jobs.push_back({bone.name, &level});
  }
  for (const Muscle& muscle : atlas.muscles) {
    for (const MeshLevel& level : muscle.meshes) jobs.push_back({muscle.name, &level});
  }
  for (const Structure& structure : atlas.structures) {
    for (const MeshLevel& level : structure.meshes) jobs.push_back({structure.name, &level});
  }
  return jobs;
}

}  // namespace

AtlasMeshes read_atlas_meshes(const Atlas& atlas, const std::filesystem::path& dir, int threads) {
  const std::vector<MeshJob> jobs = mesh_jobs(atlas);
  std::vector<mesh::IndexedMesh> read(jobs.size());
  parallel_for(jobs.size(), threads,
               [&](std::size_t i) { read[i] = mesh::read_mesh(dir / jobs[i].level->file); });
  AtlasMeshes meshes;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    meshes[jobs[i].element][jobs[i].level->level] = std::move(read[i]);
  }
  return meshes;
}

void write_atlas_with_meshes(const Atlas& atlas, const AtlasMeshes& meshes,
                             const std::filesystem::path& dir, int threads) {
  const std::vector<MeshJob> jobs = mesh_jobs(atlas);
  std::vector<const mesh::IndexedMesh*> source(jobs.size());
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const auto element = meshes.find(jobs[i].element);
    const bool found = element != meshes.end() && element->second.contains(jobs[i].level->level);
    if (!found) {
      throw InvalidInputError("atlas '" + atlas.name + "': no '" + jobs[i].level->level +
                              "' mesh for '" + jobs[i].element + "' to write");
    }
    source[i] = &element->second.at(jobs[i].level->level);
  }
  parallel_for(jobs.size(), threads, [&](std::size_t i) {
    const std::filesystem::path file = dir / jobs[i].level->file;
    std::filesystem::create_directories(file.parent_path());
    mesh::write_mesh(*source[i], file);
  });
  write_atlas_manifest(atlas, dir);
}

}  // namespace mmm::atlas

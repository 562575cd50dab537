#pragma once
// Every mesh of an atlas in memory: element (bone, muscle or structure) -> level
// ("full", "lod1", ...) -> mesh, read from and written to the atlas folder
// at the files its MeshLevels name.

#include <filesystem>
#include <map>
#include <string>

#include "core/atlas/atlas.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

using AtlasMeshes = std::map<std::string, std::map<std::string, mesh::IndexedMesh>>;

// Reads every level of every bone, muscle and structure (threads > 1: in parallel).
// Throws IoError naming the file that cannot be read.
AtlasMeshes read_atlas_meshes(const Atlas& atlas, const std::filesystem::path& dir,
                              int threads = 2);

// Writes every mesh at its MeshLevel file under `dir`, then the manifest.
// Throws InvalidInputError when a mesh of the atlas is missing from `meshes`,
// IoError when a file cannot be written.
void write_atlas_with_meshes(const Atlas& atlas, const AtlasMeshes& meshes,
                             const std::filesystem::path& dir, int threads = 2);

}  // namespace mmm::atlas

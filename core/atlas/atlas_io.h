#pragma once
// An atlas on disk: a folder holding `atlas.yaml` (the manifest, structure
// defined by schemas/atlas.schema.yaml) and the meshes it names (binary PLY,
// mm, relative paths). Reading checks the manifest and every reference
// between its elements; meshes are read on demand (load_mesh).
//
//   mmm_atlas: 1
//   name: vhf_right_leg
//   bones:
//     - name: femur_r
//       tags: [bone, right, thigh]
//       meshes: [{level: full, file: meshes/femur_r/full.ply, faces: 9000}, ...]
//       frame: {origin: [x, y, z], rotation: [[...], [...], [...]]}
//       parent_joint: hip_r
//   joints: [...]  muscles: [...]  landmarks: [...]  markers: [...]  regions: [...]

#include <filesystem>
#include <string>

#include "core/atlas/atlas.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

inline constexpr const char* kManifestFile = "atlas.yaml";
inline constexpr int kAtlasFormat = 1;

// Writes `dir`/atlas.yaml (the meshes must already be in place; their files
// are not checked here). Numbers are written with full precision, so
// write -> read reproduces every value exactly. Throws IoError.
void write_atlas_manifest(const Atlas& atlas, const std::filesystem::path& dir);

// Reads `dir`/atlas.yaml. Throws IoError naming the file with line and the
// path of the offending element ("muscles[3].action_lines[0].points[2].bone:
// unknown bone 'femr_r'; did you mean 'femur_r'?") for malformed YAML, a
// missing or ill-typed field, an unknown enum value, a non-finite number, a
// duplicate name or a reference to an element that does not exist.
Atlas read_atlas(const std::filesystem::path& dir);

// The mesh of a level of a bone or muscle ("full" when `level` is empty),
// read from the atlas folder. Throws IoError when the element has no such
// level or the file cannot be read.
mesh::IndexedMesh load_mesh(const std::filesystem::path& dir, const std::vector<MeshLevel>& meshes,
                            const std::string& level = "full");

}  // namespace mmm::atlas

#pragma once
// The surface a muscle is wrapped at and its progressive outer hull (section
// 3.4.1 of the VPHOP report): built once per muscle mesh, stored beside the
// study's other artifacts and reused whenever the mesh it was built from is
// the same (equal content hash), as the reference stores its hulls.
//
// A hull folder holds hulls.json (per muscle: the hash of the wrapping
// surface it encloses, the face counts asked for and reached, volumes, the
// containment check, build time) and one binary PLY per muscle (doubles, so
// a hull read back is bit-identical; ParaView opens it).

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/mesh/mesh.h"
#include "core/mesh/progressive_hull.h"

namespace mmm::wrapping {

// The muscle's "full" mesh level (else its first) decimated to target_faces
// (0 or more than it has: the mesh as it is). Throws InvalidInputError when
// the muscle has no mesh, IoError when the file cannot be read.
mesh::IndexedMesh wrapping_surface(const atlas::Muscle& muscle,
                                   const std::filesystem::path& atlas_dir,
                                   Eigen::Index target_faces);

// SHA-256 (hex) of a mesh's content: vertex and face counts, then the
// coordinates and indices as little-endian doubles and 32-bit integers.
std::string mesh_hash(const mesh::IndexedMesh& mesh);

struct MuscleHull {
  std::string muscle;
  std::string source_hash;       // mesh_hash of the surface it encloses
  Eigen::Index faces_asked = 0;  // ProgressiveHullOptions::target_faces
  mesh::IndexedMesh hull;
  mesh::ProgressiveHullReport report;  // containment check included
  double seconds = 0.0;                // build time
};

// Builds the hull of `surface` with the containment check.
MuscleHull build_muscle_hull(const std::string& muscle, const mesh::IndexedMesh& surface,
                             Eigen::Index hull_faces);

// The stored hull of `muscle` built from `surface` with `hull_faces`, or
// nullptr (none stored, or built from another mesh or face count).
const MuscleHull* find_hull(const std::vector<MuscleHull>& hulls, const std::string& muscle,
                            const std::string& source_hash, Eigen::Index hull_faces);

// Writes hulls.json and NAME.ply per hull into `dir` (created). Throws IoError.
void write_hulls(const std::filesystem::path& dir, const std::vector<MuscleHull>& hulls);

// Reads a folder written by write_hulls. Throws IoError naming the file for
// a missing or malformed hulls.json or hull mesh, and when a hull's faces do
// not match what hulls.json records.
std::vector<MuscleHull> read_hulls(const std::filesystem::path& dir);

}  // namespace mmm::wrapping

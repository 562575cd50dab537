#include "core/wrapping/muscle_hulls.h"

#include <array>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string_view>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/hash/sha256.h"
#include "core/mesh/decimate.h"
#include "core/mesh/io/mesh_io.h"

namespace mmm::wrapping {
namespace {

static_assert(std::endian::native == std::endian::little,
              "mesh_hash hashes the in-memory bytes of doubles and ints as little-endian");

const char* const kIndexFile = "hulls.json";

template <typename Scalar>
void hash_values(hash::Sha256& sha, const Scalar* data, Eigen::Index count) {
  sha.update(std::string_view(reinterpret_cast<const char*>(data),
                              static_cast<std::size_t>(count) * sizeof(Scalar)));
}

std::string hull_file_name(const std::string& muscle) { return muscle + ".ply"; }

}  // namespace

mesh::IndexedMesh wrapping_surface(const atlas::Muscle& muscle,
                                   const std::filesystem::path& atlas_dir,
                                   Eigen::Index target_faces) {
  if (muscle.meshes.empty())
    throw InvalidInputError("muscle wrapping: muscle '" + muscle.name + "' has no mesh");
  const atlas::MeshLevel* chosen = &muscle.meshes.front();
  for (const atlas::MeshLevel& level : muscle.meshes) {
    if (level.level == "full") chosen = &level;
  }
  mesh::IndexedMesh surface = mesh::read_mesh(atlas_dir / chosen->file);
  if (target_faces > 0 && surface.F.rows() > target_faces) {
    mesh::DecimateOptions decimate;
    decimate.target_faces = target_faces;
    surface = mesh::decimate(surface, decimate);
  }
  return surface;
}

std::string mesh_hash(const mesh::IndexedMesh& mesh) {
  hash::Sha256 sha;
  const std::array<std::int64_t, 2> counts = {mesh.V.rows(), mesh.F.rows()};
  sha.update(std::string_view(reinterpret_cast<const char*>(counts.data()), sizeof(counts)));
  // Row by row, so that the storage order of the matrices does not matter.
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    const Eigen::Vector3d p = mesh.V.row(v).transpose();
    hash_values(sha, p.data(), 3);
  }
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Matrix<std::int32_t, 3, 1> face = mesh.F.row(f).transpose().cast<std::int32_t>();
    hash_values(sha, face.data(), 3);
  }
  return hash::to_hex(sha.finish());
}

MuscleHull build_muscle_hull(const std::string& muscle, const mesh::IndexedMesh& surface,
                             Eigen::Index hull_faces) {
  const auto start = std::chrono::steady_clock::now();
  MuscleHull result;
  result.muscle = muscle;
  result.source_hash = mesh_hash(surface);
  result.faces_asked = hull_faces;
  mesh::ProgressiveHullOptions options;
  options.target_faces = hull_faces;
  try {
    result.hull = mesh::progressive_hull(surface, options, &result.report);
  } catch (const InvalidInputError& e) {
    throw InvalidInputError("progressive hull of muscle '" + muscle + "': " + e.what());
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

const MuscleHull* find_hull(const std::vector<MuscleHull>& hulls, const std::string& muscle,
                            const std::string& source_hash, Eigen::Index hull_faces) {
  for (const MuscleHull& hull : hulls) {
    if (hull.muscle == muscle && hull.source_hash == source_hash && hull.faces_asked == hull_faces)
      return &hull;
  }
  return nullptr;
}

void write_hulls(const std::filesystem::path& dir, const std::vector<MuscleHull>& hulls) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw IoError(dir, "cannot create the hull folder: " + error.message());
  nlohmann::json index = nlohmann::json::array();
  for (const MuscleHull& hull : hulls) {
    mesh::write_mesh(hull.hull, dir / hull_file_name(hull.muscle));
    const mesh::ProgressiveHullReport& r = hull.report;
    index.push_back({{"muscle", hull.muscle},
                     {"file", hull_file_name(hull.muscle)},
                     {"source_hash", hull.source_hash},
                     {"faces_asked", hull.faces_asked},
                     {"faces_before", r.faces_before},
                     {"faces_after", r.faces_after},
                     {"volume_before_mm3", r.volume_before},
                     {"volume_after_mm3", r.volume_after},
                     {"vertices_outside", r.vertices_outside},
                     {"max_outside_mm", r.max_outside_mm},
                     {"seconds", hull.seconds}});
  }
  write_file_atomically(dir / kIndexFile, nlohmann::json{{"hulls", index}}.dump(2) + "\n",
                        "a hull index");
}

std::vector<MuscleHull> read_hulls(const std::filesystem::path& dir) {
  const std::filesystem::path index_path = dir / kIndexFile;
  std::ifstream stream(index_path, std::ios::binary);
  if (!stream) {
    throw IoError(index_path,
                  "no hull index; hint: connect the 'hulls' output of a build_hulls node");
  }
  const std::string text((std::istreambuf_iterator<char>(stream)),
                         std::istreambuf_iterator<char>());
  std::vector<MuscleHull> hulls;
  try {
    const nlohmann::json index = parse_json(text);
    for (const nlohmann::json& entry : index.at("hulls")) {
      MuscleHull hull;
      hull.muscle = entry.at("muscle").get<std::string>();
      hull.source_hash = entry.at("source_hash").get<std::string>();
      hull.faces_asked = entry.at("faces_asked").get<Eigen::Index>();
      mesh::ProgressiveHullReport& r = hull.report;
      r.faces_before = entry.at("faces_before").get<Eigen::Index>();
      r.faces_after = entry.at("faces_after").get<Eigen::Index>();
      r.volume_before = entry.at("volume_before_mm3").get<double>();
      r.volume_after = entry.at("volume_after_mm3").get<double>();
      r.vertices_outside = entry.at("vertices_outside").get<int>();
      r.max_outside_mm = entry.at("max_outside_mm").get<double>();
      hull.seconds = entry.at("seconds").get<double>();
      const std::string file = entry.at("file").get<std::string>();
      if (file.find('/') != std::string::npos || file.find("..") != std::string::npos)
        throw IoError(index_path, "hull file '" + file + "' is not a plain name");
      hull.hull = mesh::read_mesh(dir / file);
      if (hull.hull.F.rows() != r.faces_after) {
        throw IoError(dir / file, "holds " + std::to_string(hull.hull.F.rows()) +
                                      " faces, the index records " + std::to_string(r.faces_after) +
                                      "; hint: rebuild the hulls");
      }
      hulls.push_back(std::move(hull));
    }
  } catch (const nlohmann::json::exception& e) {
    throw IoError(index_path,
                  "malformed hull index (" + std::string(e.what()) + "); hint: rebuild the hulls");
  }
  return hulls;
}

}  // namespace mmm::wrapping

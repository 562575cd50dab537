#pragma once
// What `mmm mesh info` and `mmm mesh survey` report about one mesh: its
// health (check_mesh) and its measures (mass_properties), as text for people
// and JSON for programs.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh.h"
#include "core/mesh/mesh_check.h"

namespace mmm::app {

struct MeshSummary {
  std::filesystem::path file;
  mesh::MeshCheckReport check;
  mesh::MassProperties properties;
  Eigen::AlignedBox3d bounds;
  mesh::OrientedBox oriented_box;

  // Volume and centroid of the solid are properties of the shape only when
  // the surface is watertight.
  [[nodiscard]] bool has_volume() const { return check.watertight() && properties.solid; }
  // Watertight with outward normals (positive enclosed volume).
  [[nodiscard]] bool outward() const { return has_volume() && properties.volume > 0; }
};

MeshSummary summarize_mesh(const mesh::IndexedMesh& mesh, const std::filesystem::path& file);

// `units` names the length unit of the coordinates ("mm" unless scaled).
nlohmann::json to_json(const MeshSummary& summary, const std::string& units);
std::string to_text(const MeshSummary& summary, const std::string& units);

}  // namespace mmm::app

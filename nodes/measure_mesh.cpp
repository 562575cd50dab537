#include "nodes/measure_mesh.h"

#include <nlohmann/json.hpp>

#include "core/mesh/io/ply.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "nodes/mesh_check_json.h"

namespace mmm::nodes {
namespace {

nlohmann::json vec(const Eigen::Vector3d& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

}  // namespace

workflow::NodeSpec MeasureMesh::spec() {
  using workflow::port::Mesh;
  using workflow::port::Report;
  return workflow::NodeSpec{"measure_mesh", 1,
                            "Health check (closed, manifold, oriented) and measures of a mesh"}
      .input<Mesh>("mesh", "Surface to measure")
      .output<Report>("report",
                      "JSON: check figures, area (mm^2), volume (mm^3), centroid, principal axes");
}

void MeasureMesh::run(workflow::NodeContext& context) {
  const mesh::IndexedMesh surface = mesh::read_ply(context.input("mesh").path);
  const mesh::MeshCheckReport c = mesh::check_mesh(surface);
  const mesh::MassProperties p = mesh::mass_properties(surface);
  const Eigen::AlignedBox3d box = mesh::bounding_box(surface);
  // Volume and solid centroid are properties of the shape only for a
  // watertight surface.
  const bool has_volume = c.watertight() && p.solid;

  nlohmann::json report;
  report["units"] = "mm";
  report["check"] = mesh_check_json(c);
  report["mass_properties"] = {
      {"area", p.area},
      {"volume", has_volume ? nlohmann::json(p.volume) : nlohmann::json()},
      {"centroid", vec(p.centroid)},
      {"centroid_of", has_volume ? "solid" : "surface"},
      {"principal_axes",
       {vec(p.principal_axes.col(0)), vec(p.principal_axes.col(1)), vec(p.principal_axes.col(2))}},
      {"principal_moments", vec(p.principal_moments)},
      {"bounding_box",
       {{"min", vec(box.min())}, {"max", vec(box.max())}, {"size", vec(box.sizes())}}}};
  context.set_output("report", report.dump(2));
}

}  // namespace mmm::nodes

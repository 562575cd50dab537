#include "nodes/measure_mesh.h"

#include <nlohmann/json.hpp>

#include "core/mesh/io/ply.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"

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
  report["check"] = {{"vertices", c.vertices},
                     {"faces", c.faces},
                     {"edges", c.edges},
                     {"boundary_edges", c.boundary_edges},
                     {"boundary_loops", c.boundary_loops},
                     {"non_manifold_edges", c.non_manifold_edges},
                     {"non_manifold_vertices", c.non_manifold_vertices},
                     {"inconsistently_oriented_edges", c.inconsistently_oriented_edges},
                     {"degenerate_faces", c.degenerate_faces},
                     {"duplicate_vertices", c.duplicate_vertices},
                     {"unreferenced_vertices", c.unreferenced_vertices},
                     {"connected_components", c.connected_components},
                     {"euler_characteristic", c.euler_characteristic},
                     {"closed", c.closed()},
                     {"manifold", c.manifold()},
                     {"orientation_consistent", c.orientation_consistent()},
                     {"watertight", c.watertight()},
                     {"problems", c.problems()}};
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

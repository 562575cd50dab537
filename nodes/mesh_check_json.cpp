#include "nodes/mesh_check_json.h"

namespace mmm::nodes {

nlohmann::json mesh_check_json(const mesh::MeshCheckReport& report) {
  const mesh::MeshCheckReport& c = report;
  return {{"vertices", c.vertices},
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
}

}  // namespace mmm::nodes

#pragma once
// Node `measure_mesh`: health and measures of a Mesh as a Report.
//
//   input  mesh    Mesh    surface to measure (mm)
//   output report  Report  JSON (keys sorted, 2-space indent):
//     {"units": "mm",
//      "check": {vertices, faces, edges, boundary_edges, boundary_loops,
//                non_manifold_edges, non_manifold_vertices,
//                inconsistently_oriented_edges, degenerate_faces,
//                duplicate_vertices, unreferenced_vertices,
//                connected_components, euler_characteristic, closed,
//                manifold, orientation_consistent, watertight, problems[]},
//      "mass_properties": {area (mm^2), volume (mm^3, null unless the mesh is
//                watertight), centroid [3] (mm), centroid_of ("solid" or
//                "surface"), principal_axes [3][3] (unit, columns as rows),
//                principal_moments [3], bounding_box {min, max, size} (mm)}}

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct MeasureMesh {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

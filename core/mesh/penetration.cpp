#include "core/mesh/penetration.h"

#include <cmath>

namespace mmm::mesh {

PenetrationReport penetration(const IndexedMesh& a, const SignedDistance& b) {
  validate_indices_and_coordinates(a);
  PenetrationReport report;
  for (Eigen::Index v = 0; v < a.num_vertices(); ++v) {
    const Eigen::Vector3d point = a.V.row(v).transpose();
    // The winding number decides; the closest point is only needed inside.
    if (!b.winding().is_inside(point)) continue;
    const auto index = static_cast<int>(v);
    report.inside_vertices.push_back(index);
    const double depth = std::sqrt(b.tree().closest_point(point).squared_distance);
    if (report.deepest_vertex < 0 || depth > report.max_depth) {
      report.max_depth = depth;
      report.deepest_vertex = index;
    }
  }
  report.vertices_inside = static_cast<int>(report.inside_vertices.size());
  return report;
}

PenetrationReport penetration(const IndexedMesh& a, const IndexedMesh& b) {
  const SignedDistance distance(b);
  return penetration(a, distance);
}

}  // namespace mmm::mesh

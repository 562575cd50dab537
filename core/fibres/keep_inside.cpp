#include "core/fibres/keep_inside.h"

#include <Eigen/Geometry>

namespace mmm::fibres {

using Eigen::Index;
using Eigen::Vector3d;

int keep_inside(std::vector<Fibre>& fibres, const mesh::WindingNumber& inside, double margin_mm) {
  const mesh::AabbTree& tree = inside.tree();
  const mesh::IndexedMesh& surface = tree.mesh();
  int moved = 0;
  for (Fibre& fibre : fibres) {
    for (Index k = 0; k < fibre.rows(); ++k) {
      const Vector3d p = fibre.row(k).transpose();
      if (inside.is_inside(p)) {
        continue;
      }
      const mesh::AabbTree::ClosestPoint closest = tree.closest_point(p);
      const Vector3d a = surface.V.row(surface.F(closest.face, 0)).transpose();
      const Vector3d b = surface.V.row(surface.F(closest.face, 1)).transpose();
      const Vector3d c = surface.V.row(surface.F(closest.face, 2)).transpose();
      const Vector3d normal = (b - a).cross(c - a).normalized();
      const bool end = k == 0 || k + 1 == fibre.rows();
      fibre.row(k) = (closest.point - (end ? 0.0 : margin_mm) * normal).transpose();
      ++moved;
    }
  }
  return moved;
}

}  // namespace mmm::fibres

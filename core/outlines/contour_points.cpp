#include "core/outlines/contour_points.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

namespace mmm::outlines {

std::vector<ContourPoint> contour_points(const mesh::IndexedMesh& surface,
                                         const image::RadiographView& view) {
  const Eigen::Index nv = surface.V.rows();
  Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(nv, 3);
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    const Eigen::Vector3d a = surface.V.row(surface.F(f, 0));
    const Eigen::Vector3d b = surface.V.row(surface.F(f, 1));
    const Eigen::Vector3d c = surface.V.row(surface.F(f, 2));
    const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();  // 2 x area
    for (int k = 0; k < 3; ++k) normals.row(surface.F(f, k)) += n;
  }
  Eigen::VectorXd side(nv);
  for (Eigen::Index i = 0; i < nv; ++i) {
    const Eigen::Vector3d x = surface.V.row(i).transpose();
    const Eigen::Vector3d ray = x - image::source_for(view, x);
    const double length = normals.row(i).norm();
    if (length > 0) normals.row(i) /= length;
    side[i] = normals.row(i).dot(ray.normalized());
  }
  // Every undirected edge once.
  std::vector<std::pair<int, int>> edges;
  edges.reserve(static_cast<std::size_t>(surface.F.rows()) * 3);
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = surface.F(f, k);
      const int b = surface.F(f, (k + 1) % 3);
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::ranges::sort(edges);
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<ContourPoint> out;
  for (const auto& [a, b] : edges) {
    const double ga = side[a];
    const double gb = side[b];
    if (!(ga * gb < 0)) continue;
    ContourPoint point;
    point.vertex_a = a;
    point.vertex_b = b;
    point.t = ga / (ga - gb);
    point.position =
        (1 - point.t) * surface.V.row(a).transpose() + point.t * surface.V.row(b).transpose();
    if (image::depth_mm(view, point.position) <= 0) continue;
    const Eigen::Vector3d normal =
        ((1 - point.t) * normals.row(a) + point.t * normals.row(b)).transpose();
    const Eigen::Vector2d projected = projection_jacobian(view, point.position) * normal;
    const double expected =
        projection_jacobian(view, point.position).norm() / std::sqrt(2.0) * normal.norm();
    if (!(projected.norm() > 0.2 * expected)) continue;
    point.pixel = image::project(view, point.position);
    point.outward = projected.normalized();
    out.push_back(point);
  }
  return out;
}

}  // namespace mmm::outlines

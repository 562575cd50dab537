#include "core/mesh/surface_distance.h"

#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "core/mesh/mass_matrix.h"

namespace mmm::mesh {

Eigen::VectorXd distances_to_surface(const Eigen::MatrixX3d& points, const AabbTree& surface) {
  Eigen::VectorXd distances(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    distances[i] = std::sqrt(surface.closest_point(points.row(i).transpose()).squared_distance);
  }
  return distances;
}

SurfaceDistance surface_distance(const IndexedMesh& a, const IndexedMesh& b) {
  const AabbTree tree_a(a);
  const AabbTree tree_b(b);
  const Eigen::VectorXd a_to_b = distances_to_surface(a.V, tree_b);
  const Eigen::VectorXd b_to_a = distances_to_surface(b.V, tree_a);
  Eigen::VectorXd weights(a.V.rows() + b.V.rows());
  weights << mass_matrix(a.V, a.F, MassType::kBarycentric).diagonal(),
      mass_matrix(b.V, b.F, MassType::kBarycentric).diagonal();
  Eigen::VectorXd distances(weights.size());
  distances << a_to_b, b_to_a;

  SurfaceDistance result;
  result.samples = distances.size();
  const double total = weights.sum();
  if (result.samples == 0 || !(total > 0)) return result;
  result.mean_mm = distances.dot(weights) / total;
  result.max_mm = distances.maxCoeff();
  std::vector<Eigen::Index> order(static_cast<std::size_t>(distances.size()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::sort(order.begin(), order.end(),
            [&](Eigen::Index i, Eigen::Index j) { return distances[i] < distances[j]; });
  double cumulative = 0;
  for (const Eigen::Index i : order) {
    cumulative += weights[i];
    if (cumulative >= 0.95 * total) {
      result.p95_mm = distances[i];
      break;
    }
  }
  return result;
}

}  // namespace mmm::mesh

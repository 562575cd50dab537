#include "core/mesh/signed_distance.h"

#include <cmath>

namespace mmm::mesh {

SignedDistance::SignedDistance(const IndexedMesh& mesh) : SignedDistance(mesh, Options{}) {}

SignedDistance::SignedDistance(const IndexedMesh& mesh, const Options& options)
    : tree_(std::make_unique<AabbTree>(mesh, options.tree)), winding_(*tree_, options.winding) {}

double SignedDistance::at(const Eigen::Vector3d& q) const {
  const double distance = std::sqrt(tree_->closest_point(q).squared_distance);
  return winding_.is_inside(q) ? -distance : distance;
}

Eigen::VectorXd SignedDistance::at(const Eigen::MatrixX3d& points) const {
  Eigen::VectorXd distances(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    distances[i] = at(Eigen::Vector3d(points.row(i).transpose()));
  }
  return distances;
}

}  // namespace mmm::mesh

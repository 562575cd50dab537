#include "core/wrapping/hull_embedding.h"

#include <Eigen/SVD>
#include <algorithm>
#include <string>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::wrapping {
namespace {

// The rotation closest to m (Frobenius), by SVD with the reflection removed.
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  if ((u * v.transpose()).determinant() < 0.0) u.col(2) = -u.col(2);
  return u * v.transpose();
}

}  // namespace

HullEmbedding::HullEmbedding(const mesh::IndexedMesh& rest_hull, const Eigen::MatrixX3d& rest_fine)
    : rest_hull_(rest_hull.V), hull_faces_(rest_hull.F) {
  if (rest_hull.F.rows() == 0) throw InvalidInputError("hull embedding: the hull has no face");
  if (!rest_fine.allFinite())
    throw InvalidInputError("hull embedding: the fine surface has a non-finite coordinate");
  const mesh::AabbTree tree(rest_hull);  // validates indices and coordinates
  const auto hull_vertices = static_cast<std::size_t>(rest_hull.V.rows());
  neighbours_.resize(hull_vertices);
  for (Eigen::Index f = 0; f < rest_hull.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = rest_hull.F(f, c);
      const int b = rest_hull.F(f, (c + 1) % 3);
      neighbours_[static_cast<std::size_t>(a)].push_back(b);
      neighbours_[static_cast<std::size_t>(b)].push_back(a);
    }
  }
  for (std::vector<int>& ring : neighbours_) {
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  }
  const Eigen::Index n = rest_fine.rows();
  face_.resize(n);
  barycentric_.resize(n, 3);
  offset_.resize(n, 3);
  for (Eigen::Index v = 0; v < n; ++v) {
    const Eigen::Vector3d p = rest_fine.row(v).transpose();
    const mesh::AabbTree::ClosestPoint closest = tree.closest_point(p);
    face_(v) = closest.face;
    barycentric_.row(v) = closest.barycentric.transpose();
    offset_.row(v) = (p - closest.point).transpose();
  }
}

HullEmbedding::Transfer HullEmbedding::transfer(const Eigen::MatrixX3d& hull) const {
  if (hull.rows() != rest_hull_.rows()) {
    throw InvalidInputError("hull embedding: " + std::to_string(hull.rows()) +
                            " hull vertices given, the rest hull has " +
                            std::to_string(rest_hull_.rows()));
  }
  std::vector<Eigen::Matrix3d> vertex_rotations(static_cast<std::size_t>(hull.rows()));
  for (Eigen::Index k = 0; k < hull.rows(); ++k) {
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const int j : neighbours_[static_cast<std::size_t>(k)]) {
      covariance +=
          (hull.row(j) - hull.row(k)).transpose() * (rest_hull_.row(j) - rest_hull_.row(k));
    }
    vertex_rotations[static_cast<std::size_t>(k)] = nearest_rotation(covariance);
  }
  Transfer result;
  const Eigen::Index n = face_.rows();
  result.positions.resize(n, 3);
  result.rotations.resize(static_cast<std::size_t>(n));
  for (Eigen::Index v = 0; v < n; ++v) {
    Eigen::Vector3d on_hull = Eigen::Vector3d::Zero();
    Eigen::Matrix3d blend = Eigen::Matrix3d::Zero();
    for (int c = 0; c < 3; ++c) {
      const int k = hull_faces_(face_(v), c);
      on_hull += barycentric_(v, c) * hull.row(k).transpose();
      blend += barycentric_(v, c) * vertex_rotations[static_cast<std::size_t>(k)];
    }
    const Eigen::Matrix3d rotation = nearest_rotation(blend);
    result.positions.row(v) = (on_hull + rotation * offset_.row(v).transpose()).transpose();
    result.rotations[static_cast<std::size_t>(v)] = rotation;
  }
  return result;
}

double HullEmbedding::max_offset() const {
  return offset_.rows() == 0 ? 0.0 : offset_.rowwise().norm().maxCoeff();
}

}  // namespace mmm::wrapping

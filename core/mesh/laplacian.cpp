#include "core/mesh/laplacian.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh/mesh.h"
#include "core/mesh/triangle.h"

namespace mmm::mesh {
namespace {

using Triplet = Eigen::Triplet<double>;

}  // namespace

Eigen::SparseMatrix<double> cotangent_laplacian(const Eigen::MatrixX3d& V,
                                                const Eigen::MatrixX3i& F) {
  validate_indices_and_coordinates(IndexedMesh{V, F});
  std::vector<Triplet> triplets;
  triplets.reserve(static_cast<size_t>(12 * F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const std::array<Eigen::Vector3d, 3> p = {
        V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose()};
    const double double_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (is_numerically_degenerate(p, double_area)) continue;
    for (int k = 0; k < 3; ++k) {
      // Corner k sees the edge (i, j) opposite to it under the angle theta_k;
      // cot theta_k = (u . v) / |u x v| with |u x v| = twice the area.
      const int i = F(f, (k + 1) % 3);
      const int j = F(f, (k + 2) % 3);
      const Eigen::Vector3d u = p[(k + 1) % 3] - p[k];
      const Eigen::Vector3d v = p[(k + 2) % 3] - p[k];
      const double half_cot = 0.5 * u.dot(v) / double_area;
      triplets.emplace_back(i, j, half_cot);
      triplets.emplace_back(j, i, half_cot);
      triplets.emplace_back(i, i, -half_cot);
      triplets.emplace_back(j, j, -half_cot);
    }
  }
  Eigen::SparseMatrix<double> L(V.rows(), V.rows());
  L.setFromTriplets(triplets.begin(), triplets.end());
  return L;
}

Eigen::SparseMatrix<double> uniform_laplacian(const Eigen::MatrixX3i& F,
                                              Eigen::Index num_vertices) {
  if (num_vertices < 0) {
    throw InvalidInputError("uniform_laplacian: num_vertices must be >= 0, got " +
                            std::to_string(num_vertices));
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (F(f, k) < 0 || F(f, k) >= num_vertices) {
        throw InvalidInputError("uniform_laplacian: face " + std::to_string(f) +
                                " refers to vertex " + std::to_string(F(f, k)) + " but only " +
                                std::to_string(num_vertices) +
                                " vertices were declared; pass #V of the mesh as num_vertices");
      }
    }
  }
  // Adjacency with every directed edge once per face using it; the summed
  // duplicates (2 on an interior edge) are then reset to 1.
  std::vector<Triplet> triplets;
  triplets.reserve(static_cast<size_t>(6 * F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, k);
      const int j = F(f, (k + 1) % 3);
      if (i == j) continue;
      triplets.emplace_back(i, j, 1.0);
      triplets.emplace_back(j, i, 1.0);
    }
  }
  Eigen::SparseMatrix<double> adjacency(num_vertices, num_vertices);
  adjacency.setFromTriplets(triplets.begin(), triplets.end());

  triplets.clear();
  triplets.reserve(static_cast<size_t>(adjacency.nonZeros() + num_vertices));
  for (Eigen::Index col = 0; col < adjacency.outerSize(); ++col) {
    double degree = 0.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(adjacency, col); it; ++it) {
      triplets.emplace_back(it.row(), it.col(), 1.0);
      degree += 1.0;
    }
    if (degree > 0.0) triplets.emplace_back(col, col, -degree);
  }
  Eigen::SparseMatrix<double> L(num_vertices, num_vertices);
  L.setFromTriplets(triplets.begin(), triplets.end());
  return L;
}

}  // namespace mmm::mesh

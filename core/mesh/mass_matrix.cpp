#include "core/mesh/mass_matrix.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/triangle.h"

namespace mmm::mesh {
namespace {

// Shares of one non-degenerate triangle's area for corners 0, 1, 2.
std::array<double, 3> voronoi_shares(const std::array<Eigen::Vector3d, 3>& p, double area) {
  std::array<double, 3> dots{};
  for (int k = 0; k < 3; ++k) {
    dots[k] = (p[(k + 1) % 3] - p[k]).dot(p[(k + 2) % 3] - p[k]);
  }
  for (int k = 0; k < 3; ++k) {
    if (dots[k] < 0.0) {
      // Obtuse at corner k: the circumcentre lies outside the triangle.
      std::array<double, 3> shares{};
      shares.fill(0.25 * area);
      shares[k] = 0.5 * area;
      return shares;
    }
  }
  // Non-obtuse: corner k gets (|e_kj|^2 cot(angle at i) + |e_ki|^2 cot(angle
  // at j)) / 8, with cot(angle at c) = dots[c] / (2 area).
  std::array<double, 3> shares{};
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3;
    const int j = (k + 2) % 3;
    const double cot_i = dots[i] / (2.0 * area);
    const double cot_j = dots[j] / (2.0 * area);
    shares[k] = ((p[j] - p[k]).squaredNorm() * cot_i + (p[i] - p[k]).squaredNorm() * cot_j) / 8.0;
  }
  return shares;
}

}  // namespace

Eigen::SparseMatrix<double> mass_matrix(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& F,
                                        MassType type) {
  validate_indices_and_coordinates(IndexedMesh{V, F});
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(V.rows());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const std::array<Eigen::Vector3d, 3> p = {
        V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose()};
    const double double_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (is_numerically_degenerate(p, double_area)) continue;
    const double area = 0.5 * double_area;
    std::array<double, 3> shares{};
    if (type == MassType::kBarycentric) {
      shares.fill(area / 3.0);
    } else {
      shares = voronoi_shares(p, area);
    }
    for (int k = 0; k < 3; ++k) mass(F(f, k)) += shares[k];
  }
  Eigen::SparseMatrix<double> M(V.rows(), V.rows());
  M.reserve(Eigen::VectorXi::Ones(V.rows()));
  for (Eigen::Index v = 0; v < V.rows(); ++v) M.insert(v, v) = mass(v);
  M.makeCompressed();
  return M;
}

}  // namespace mmm::mesh

#include "core/scaling/bone_energy.h"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <cmath>

#include "core/errors.h"
#include "core/mesh/laplacian.h"

namespace mmm::scaling {
namespace {

using Eigen::Matrix4d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::Vector4d;
using Eigen::VectorXd;
using SparseMatrix = Eigen::SparseMatrix<double>;

// The affine part about the centroid: row k of the result's coordinates is
// g_k . (v - c, 1), g_k = (M.row(k), t_k) with t = A(c).
Eigen::Matrix<double, 4, 3> centred_parameters(const Eigen::Affine3d& map, const Vector3d& c) {
  Eigen::Matrix<double, 4, 3> g;
  g.topRows<3>() = map.linear().transpose();
  g.row(3) = (map * c).transpose();
  return g;
}

Eigen::Affine3d affine_from(const Eigen::Matrix<double, 4, 3>& g, const Vector3d& c) {
  Eigen::Affine3d map = Eigen::Affine3d::Identity();
  map.linear() = g.topRows<3>().transpose();
  map.translation() = g.row(3).transpose() - map.linear() * c;
  return map;
}

std::vector<double> residuals(const std::vector<PointTerm>& terms, const Eigen::MatrixX3d& placed) {
  std::vector<double> out;
  out.reserve(terms.size());
  for (const PointTerm& term : terms) {
    out.push_back((reconstruct(term.anchor, placed) - term.target).norm());
  }
  return out;
}

}  // namespace

BoneSolution solve_bone(const mesh::IndexedMesh& rest, const Eigen::Affine3d& prior,
                        const std::vector<PointTerm>& terms, const BoneEnergyOptions& options) {
  mesh::validate_indices_and_coordinates(rest);
  for (const PointTerm& term : terms) {
    if (!term.target.allFinite() || !term.rest.allFinite() || !(term.weight > 0.0)) {
      throw InvalidInputError("bone energy: point term '" + term.name +
                              "' has a non-finite position or a weight that is not positive");
    }
  }
  BoneSolution solution;
  const Eigen::Index n = rest.V.rows();
  const Vector3d c = rest.V.colwise().mean().transpose();
  const Eigen::MatrixX3d Y = rest.V.rowwise() - c.transpose();

  // Closed form: the prior already meets every term.
  solution.affine = prior;
  solution.vertices = (Y * prior.linear().transpose()).rowwise() + (prior * c).transpose();
  solution.residual_mm = residuals(terms, solution.vertices);
  bool met = true;
  for (const double r : solution.residual_mm) met = met && r <= options.closed_form_tolerance_mm;
  if (met) return solution;

  const double radius = std::sqrt(Y.rowwise().squaredNorm().mean());
  const SparseMatrix L = mesh::cotangent_laplacian(rest.V, rest.F);
  SparseMatrix K = options.laplacian_weight * SparseMatrix(L.transpose() * L);
  const double gauge = options.gauge_weight * K.diagonal().mean();
  // Point rows: A (anchors), P (homogeneous centred rest points), W (weights).
  const auto m = static_cast<Eigen::Index>(terms.size());
  SparseMatrix A(m, n);
  std::vector<Eigen::Triplet<double>> entries;
  MatrixXd P(m, 4);
  VectorXd w(m);
  Eigen::MatrixX3d targets(m, 3);
  for (Eigen::Index j = 0; j < m; ++j) {
    const PointTerm& term = terms[static_cast<std::size_t>(j)];
    for (std::size_t i = 0; i < term.anchor.vertices.size(); ++i) {
      entries.emplace_back(j, term.anchor.vertices[i], term.anchor.weights[i]);
    }
    P.block<1, 3>(j, 0) = (term.rest - c).transpose();
    P(j, 3) = 1.0;
    w[j] = term.weight;
    targets.row(j) = term.target.transpose();
  }
  A.setFromTriplets(entries.begin(), entries.end());
  K += SparseMatrix(A.transpose() * w.asDiagonal() * A);
  SparseMatrix identity(n, n);
  identity.setIdentity();
  K += gauge * identity;
  Eigen::SimplicialLDLT<SparseMatrix> factor(K);
  if (factor.info() != Eigen::Success) {
    throw SolverError("bone energy: the sparse LDLT factorisation of the detail term failed");
  }
  const MatrixXd K_dg = A.transpose() * w.asDiagonal() * P;  // n x 4
  const Vector4d D2(radius * radius, radius * radius, radius * radius, 1.0);
  const Matrix4d K_gg = P.transpose() * w.asDiagonal() * P +
                        Matrix4d(options.affine_prior_weight * D2.asDiagonal());
  const MatrixXd Z = factor.solve(K_dg);  // K_dd^-1 K_dg
  const Matrix4d S = K_gg - K_dg.transpose() * Z;
  const Eigen::LDLT<Matrix4d> schur(S);
  const Eigen::Matrix<double, 4, 3> g0 = centred_parameters(prior, c);
  Eigen::Matrix<double, 4, 3> g;
  for (int k = 0; k < 3; ++k) {
    const VectorXd b_d = A.transpose() * (w.asDiagonal() * targets.col(k));
    const Vector4d b_g = P.transpose() * (w.asDiagonal() * targets.col(k)) +
                         Vector4d(options.affine_prior_weight * D2.cwiseProduct(g0.col(k)));
    const VectorXd e = factor.solve(b_d);
    g.col(k) = schur.solve(b_g - K_dg.transpose() * e);
    const VectorXd d = e - Z * g.col(k);
    solution.vertices.col(k) = Y * g.col(k).head<3>() + VectorXd::Constant(n, g(3, k)) + d;
  }
  if (!solution.vertices.allFinite()) {
    throw SolverError("bone energy: the solution is not finite (degenerate point terms?)");
  }
  solution.affine = affine_from(g, c);
  solution.solved = true;
  solution.residual_mm = residuals(terms, solution.vertices);
  return solution;
}

}  // namespace mmm::scaling

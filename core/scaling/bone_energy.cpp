#include "core/scaling/bone_energy.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/mesh/laplacian.h"
#include "core/scaling/sparse_cholesky.h"

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
  const auto place = [&](const Eigen::Affine3d& map) {
    return Eigen::MatrixX3d((Y * map.linear().transpose()).rowwise() + (map * c).transpose());
  };

  // The prior already meets every term: E(0, g0) = 0.
  solution.affine = prior;
  solution.vertices = place(prior);
  solution.residual_mm = residuals(terms, solution.vertices);
  if (std::ranges::all_of(solution.residual_mm,
                          [&](double r) { return r <= options.closed_form_tolerance_mm; })) {
    return solution;
  }

  // 1. The affine part: the global point terms' least squares, the prior
  //    filling the directions they leave open.
  const double radius = std::sqrt(Y.rowwise().squaredNorm().mean());
  const auto m = static_cast<Eigen::Index>(terms.size());
  MatrixXd P(m, 4);
  VectorXd w(m);
  Eigen::MatrixX3d targets(m, 3);
  for (Eigen::Index j = 0; j < m; ++j) {
    const PointTerm& term = terms[static_cast<std::size_t>(j)];
    P.block<1, 3>(j, 0) = (term.rest - c).transpose();
    P(j, 3) = 1.0;
    w[j] = term.weight;
    targets.row(j) = term.target.transpose();
  }
  // Local points take no part in the affine fit (weight 0 in its normal matrix).
  VectorXd w_affine = w;
  for (Eigen::Index j = 0; j < m; ++j) {
    if (terms[static_cast<std::size_t>(j)].falloff_radius_mm > 0.0) w_affine[j] = 0.0;
  }
  // In units of mm (h = D g, D = diag(R, R, R, 1)), the points' normal
  // matrix; its eigenvectors with enough weight are fitted, the others keep
  // the prior (a point pair 1 mm apart must not decide how the whole bone
  // shears).
  const Vector4d D(radius, radius, radius, 1.0);
  const Matrix4d normal = D.cwiseInverse().asDiagonal() *
                          (P.transpose() * w_affine.asDiagonal() * P) *
                          D.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Matrix4d> eigen(normal);
  const double largest = eigen.eigenvalues().maxCoeff();
  Matrix4d fitted_inverse = Matrix4d::Zero();
  solution.free_directions = 0;
  for (int i = 0; i < 4; ++i) {
    const double lambda = eigen.eigenvalues()[i];
    if (largest > 0.0 && lambda > options.determined_fraction * largest) {
      fitted_inverse +=
          eigen.eigenvectors().col(i) * eigen.eigenvectors().col(i).transpose() / lambda;
    } else {
      ++solution.free_directions;
    }
  }
  const Eigen::Matrix<double, 4, 3> g0 = centred_parameters(prior, c);
  Eigen::Matrix<double, 4, 3> g;
  for (int k = 0; k < 3; ++k) {
    const VectorXd misfit = targets.col(k) - P * g0.col(k);
    const Vector4d step = D.cwiseInverse().asDiagonal() *
                          (fitted_inverse * (D.cwiseInverse().asDiagonal() *
                                             (P.transpose() * (w_affine.asDiagonal() * misfit))));
    g.col(k) = g0.col(k) + step;
  }
  solution.affine = affine_from(g, c);
  solution.vertices = place(solution.affine);

  // 1b. The local points: what they still miss, as a field that fades out
  //     within their radius, zero at the global points.
  if (std::ranges::any_of(terms, [](const PointTerm& t) { return t.falloff_radius_mm > 0.0; })) {
    std::vector<LocalPoint> points;
    points.reserve(terms.size());
    for (const PointTerm& term : terms) {
      LocalPoint point{term.rest,
                       term.target - solution.affine * term.rest,
                       term.falloff_radius_mm,
                       {},
                       term.anchor.weights};
      for (const int v : term.anchor.vertices)
        point.samples.emplace_back(rest.V.row(v).transpose());
      points.push_back(std::move(point));
    }
    solution.local = fit_local_field(points);
    solution.vertices += solution.local.displacements(rest.V);
  }
  solution.residual_mm = residuals(terms, solution.vertices);
  solution.solved = true;
  // A bend only for what the affine part misses: a local point's remaining
  // residual (a welded bone's landmark, met on its own bone) is no reason to
  // bend the whole surface.
  bool missed = false;
  for (std::size_t j = 0; j < terms.size(); ++j) {
    missed = missed || (terms[j].falloff_radius_mm <= 0.0 &&
                        solution.residual_mm[j] > options.closed_form_tolerance_mm);
  }
  if (!missed) return solution;

  // 2. The detail: what no affine map explains, as a smooth bend d with
  //    the least change of the differential coordinates.
  const SparseMatrix L = mesh::cotangent_laplacian(rest.V, rest.F);
  SparseMatrix K = options.laplacian_weight * SparseMatrix(L.transpose() * L);
  const double gauge = options.gauge_weight * K.diagonal().mean();
  SparseMatrix A(m, n);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index j = 0; j < m; ++j) {
    const PointTerm& term = terms[static_cast<std::size_t>(j)];
    for (std::size_t i = 0; i < term.anchor.vertices.size(); ++i) {
      entries.emplace_back(j, term.anchor.vertices[i], term.anchor.weights[i]);
    }
  }
  A.setFromTriplets(entries.begin(), entries.end());
  K += SparseMatrix(A.transpose() * w.asDiagonal() * A);
  SparseMatrix identity(n, n);
  identity.setIdentity();
  K += gauge * identity;
  const SparseCholesky factor(K);
  if (factor.info() != Eigen::Success) {
    throw SolverError("bone energy: the sparse Cholesky factorisation of the detail term failed");
  }
  const Eigen::MatrixX3d misfit = targets - A * solution.vertices;
  for (int k = 0; k < 3; ++k) {
    solution.vertices.col(k) +=
        factor.solve(VectorXd(A.transpose() * (w.asDiagonal() * misfit.col(k))));
  }
  if (!solution.vertices.allFinite()) {
    throw SolverError("bone energy: the solution is not finite (degenerate point terms?)");
  }
  solution.bent = true;
  solution.residual_mm = residuals(terms, solution.vertices);
  return solution;
}

}  // namespace mmm::scaling

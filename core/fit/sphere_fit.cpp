#include "core/fit/sphere_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/fit/lm_damping.h"

namespace mmm::fit {
namespace {

// Points whose variance across their thinnest direction is below this fraction
// of the variance along their widest lie in a plane up to rounding: the
// eigen-solver alone leaves ~1e-16 there for exactly coplanar points. (A
// thickness below 1e-6 of the extent; a cap that flat would have a radius 1e5
// times its width.)
constexpr double kCoplanarVarianceRatio = 1e-12;

using detail::kInitialDamping;
using detail::kMaxDamping;
using detail::kMinDamping;

// The points in normalised coordinates q = (p - mean) / spread.
struct Normalised {
  Eigen::MatrixX3d q;
  Eigen::Vector3d mean;
  double spread = 0;
};

Normalised normalise(const Eigen::MatrixX3d& points) {
  Normalised out;
  out.mean = points.colwise().mean().transpose();
  out.q = points.rowwise() - out.mean.transpose();
  out.spread = std::sqrt(out.q.squaredNorm() / static_cast<double>(points.rows()));
  if (!(out.spread > 0)) throw InvalidInputError("sphere_fit: all points coincide");
  out.q /= out.spread;
  return out;
}

void check_not_coplanar(const Eigen::MatrixX3d& q) {
  const Eigen::Matrix3d covariance = q.transpose() * q / static_cast<double>(q.rows());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d variance = solver.eigenvalues().cwiseMax(0.0);  // ascending
  const double thickness = std::sqrt(variance[0] / variance[2]);
  if (!(variance[0] >= kCoplanarVarianceRatio * variance[2])) {
    throw InvalidInputError(
        "sphere_fit: the points lie in a plane (thickness " + std::to_string(thickness) +
        " of their extent), so no unique sphere fits them; hint: sample a curved surface patch");
  }
}

// Kasa fit: |q|^2 = 2 c.q + d in the least-squares sense. Returns (c, r).
Eigen::Vector4d algebraic_fit(const Eigen::MatrixX3d& q) {
  Eigen::MatrixX4d a(q.rows(), 4);
  a.leftCols<3>() = 2.0 * q;
  a.col(3).setOnes();
  const Eigen::VectorXd b = q.rowwise().squaredNorm();
  const Eigen::Vector4d solution = a.colPivHouseholderQr().solve(b);
  const Eigen::Vector3d c = solution.head<3>();
  Eigen::Vector4d x;
  x << c, std::sqrt(std::max(0.0, solution[3] + c.squaredNorm()));
  return x;
}

// Sum of squared geometric residuals at x = (c, r); fills the normal
// equations J^T J and J^T e when given.
double geometric_cost(const Eigen::MatrixX3d& q, const Eigen::Vector4d& x,
                      Eigen::Matrix4d* jtj = nullptr, Eigen::Vector4d* jte = nullptr) {
  const Eigen::Vector3d c = x.head<3>();
  double cost = 0;
  if (jtj != nullptr) jtj->setZero();
  if (jte != nullptr) jte->setZero();
  for (Eigen::Index i = 0; i < q.rows(); ++i) {
    const Eigen::Vector3d d = q.row(i).transpose() - c;
    const double distance = d.norm();
    const double e = distance - x[3];
    cost += e * e;
    if (jtj == nullptr) continue;
    Eigen::Vector4d row;
    // d e / d c = -(q - c) / |q - c|, undefined for a point at the centre;
    // there the residual does not depend on c to first order.
    row.head<3>() = distance > 0 ? Eigen::Vector3d(-d / distance) : Eigen::Vector3d::Zero();
    row[3] = -1.0;
    *jtj += row * row.transpose();
    *jte += row * e;
  }
  return cost;
}

struct Refinement {
  Eigen::Vector4d x;
  double cost = 0;
  int iterations = 0;
  bool converged = false;
};

Refinement refine_geometric(const Eigen::MatrixX3d& q, const Eigen::Vector4d& start,
                            const SphereFitOptions& options) {
  Refinement out;
  out.x = start;
  Eigen::Matrix4d jtj;
  Eigen::Vector4d jte;
  out.cost = geometric_cost(q, out.x, &jtj, &jte);
  double damping = kInitialDamping;
  while (out.iterations < options.max_iterations) {
    if (out.cost == 0.0) {
      out.converged = true;
      break;
    }
    ++out.iterations;
    Eigen::Matrix4d system = jtj;
    system.diagonal() += damping * jtj.diagonal().cwiseMax(kMinDamping);
    const Eigen::Vector4d step = system.ldlt().solve(-jte);
    if (step.norm() <= options.tolerance * (out.x.norm() + options.tolerance)) {
      out.converged = true;
      break;
    }
    const Eigen::Vector4d candidate = out.x + step;
    Eigen::Matrix4d candidate_jtj;
    Eigen::Vector4d candidate_jte;
    const double candidate_cost = geometric_cost(q, candidate, &candidate_jtj, &candidate_jte);
    if (candidate_cost < out.cost) {
      const double decrease = (out.cost - candidate_cost) / out.cost;
      out.x = candidate;
      out.cost = candidate_cost;
      jtj = candidate_jtj;
      jte = candidate_jte;
      damping = std::max(damping / 10.0, kMinDamping);
      if (decrease < options.tolerance) {
        out.converged = true;
        break;
      }
    } else {
      damping *= 10.0;
      if (damping > kMaxDamping) {
        // No step down from here, however short: a minimum up to rounding.
        out.converged = true;
        break;
      }
    }
  }
  return out;
}

}  // namespace

SphereFitResult sphere_fit(const Eigen::MatrixX3d& points, const SphereFitOptions& options) {
  if (points.rows() < 4) {
    throw InvalidInputError("sphere_fit: needs at least 4 points, got " +
                            std::to_string(points.rows()));
  }
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    if (!points.row(i).allFinite()) {
      throw InvalidInputError("sphere_fit: point " + std::to_string(i) + " is not finite");
    }
  }
  if (options.max_iterations < 0) {
    throw InvalidInputError("sphere_fit: max_iterations must be >= 0, got " +
                            std::to_string(options.max_iterations));
  }
  const Normalised n = normalise(points);
  check_not_coplanar(n.q);

  Refinement fit;
  fit.x = algebraic_fit(n.q);
  if (options.refine) {
    fit = refine_geometric(n.q, fit.x, options);
  } else {
    fit.cost = geometric_cost(n.q, fit.x);
    fit.converged = true;
  }
  SphereFitResult out;
  out.center = n.mean + n.spread * fit.x.head<3>();
  out.radius = n.spread * fit.x[3];
  out.rms = n.spread * std::sqrt(fit.cost / static_cast<double>(points.rows()));
  out.iterations = fit.iterations;
  out.converged = fit.converged;
  if (!out.center.allFinite() || !std::isfinite(out.radius) || !std::isfinite(out.rms)) {
    throw SolverError("sphere_fit: the fit gave non-finite numbers (centre " +
                      std::to_string(out.center.x()) + ", radius " + std::to_string(out.radius) +
                      ")");
  }
  return out;
}

}  // namespace mmm::fit

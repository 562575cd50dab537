#include "core/fit/rigid_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/fit/lm_damping.h"
#include "core/fit/principal_axes.h"

namespace mmm::fit {
namespace {

// Points whose variance across their widest direction's line is below this
// fraction of the variance along it are collinear up to rounding (exactly
// collinear input leaves ~1e-16 there after the eigen-solver).
constexpr double kCollinearVarianceRatio = 1e-12;

// The cross-covariance of source and target must have a second singular value
// at least this fraction of the first, or the rotation about one axis is free.
constexpr double kRankRatio = 1e-12;

// Orthonormality tolerance of caller-given scale axes (|A^T A - I|, max entry).
constexpr double kOrthonormalTolerance = 1e-9;

using detail::kInitialDamping;
using detail::kMaxDamping;
using detail::kMinDamping;

// The weighted pairs, centred on their weighted centroids; weights sum to 1.
struct Centred {
  Eigen::MatrixX3d p;
  Eigen::MatrixX3d q;
  Eigen::VectorXd w;
  Eigen::Vector3d mean_p;
  Eigen::Vector3d mean_q;
};

void check_input(const Eigen::MatrixX3d& source, const Eigen::MatrixX3d& target,
                 const Eigen::VectorXd& weights) {
  const Eigen::Index n = source.rows();
  if (target.rows() != n) {
    throw InvalidInputError("rigid_fit: " + std::to_string(n) + " source points but " +
                            std::to_string(target.rows()) + " target points");
  }
  if (weights.size() != 0 && weights.size() != n) {
    throw InvalidInputError("rigid_fit: " + std::to_string(weights.size()) + " weights for " +
                            std::to_string(n) + " point pairs");
  }
  Eigen::Index positive = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!source.row(i).allFinite() || !target.row(i).allFinite()) {
      throw InvalidInputError("rigid_fit: point pair " + std::to_string(i) + " is not finite");
    }
    const double w = weights.size() != 0 ? weights[i] : 1.0;
    if (!(w >= 0 && std::isfinite(w))) {
      throw InvalidInputError("rigid_fit: weight " + std::to_string(i) + " is " +
                              std::to_string(w) + ", expected finite and >= 0");
    }
    if (w > 0) ++positive;
  }
  if (positive < 3) {
    throw InvalidInputError("rigid_fit: needs at least 3 point pairs of positive weight, got " +
                            std::to_string(positive));
  }
}

void check_not_collinear(const Eigen::MatrixX3d& centred, const Eigen::VectorXd& w,
                         const char* which) {
  const Eigen::Matrix3d covariance = centred.transpose() * w.asDiagonal() * centred;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d& variance = solver.eigenvalues();  // ascending
  if (!(variance[1] >= kCollinearVarianceRatio * variance[2]) || !(variance[2] > 0)) {
    throw InvalidInputError(std::string("rigid_fit: the weighted ") + which +
                            " points are collinear or coincide, so the rotation about their "
                            "line is undetermined; hint: add a pair off that line");
  }
}

Centred centre(const Eigen::MatrixX3d& source, const Eigen::MatrixX3d& target,
               const Eigen::VectorXd& weights) {
  Centred c;
  c.w = weights.size() != 0 ? weights : Eigen::VectorXd::Ones(source.rows());
  c.w /= c.w.sum();
  c.mean_p = source.transpose() * c.w;
  c.mean_q = target.transpose() * c.w;
  c.p = source.rowwise() - c.mean_p.transpose();
  c.q = target.rowwise() - c.mean_q.transpose();
  check_not_collinear(c.p, c.w, "source");
  check_not_collinear(c.q, c.w, "target");
  return c;
}

// Umeyama's closed form on centred pairs: rotation and (when wanted) scale.
struct Similarity {
  Eigen::Matrix3d rotation;
  double scale = 1.0;
};

Similarity umeyama(const Centred& c, bool with_scale) {
  const Eigen::Matrix3d h = c.q.transpose() * c.w.asDiagonal() * c.p;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d& d = svd.singularValues();
  if (!(d[1] >= kRankRatio * d[0]) || !(d[0] > 0)) {
    throw InvalidInputError(
        "rigid_fit: source and target are uncorrelated across all but one direction, so the "
        "rotation is undetermined; hint: check the correspondences");
  }
  Eigen::Vector3d e = Eigen::Vector3d::Ones();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) e[2] = -1.0;
  Similarity out;
  out.rotation = svd.matrixU() * e.asDiagonal() * svd.matrixV().transpose();
  if (with_scale) {
    const double variance_p = c.w.dot(c.p.rowwise().squaredNorm());
    out.scale = d.dot(e) / variance_p;
  }
  return out;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Weighted squared residual sum of R A diag(exp(sigma)) u_i - q_i with
// u = A^T p (centred source in the scale frame); fills the Gauss-Newton
// normal equations in (rotation increment w, sigma) when asked.
double axis_scaled_cost(const Eigen::MatrixX3d& u, const Centred& c, const Eigen::Matrix3d& axes,
                        const Eigen::Matrix3d& rotation, const Eigen::Vector3d& sigma,
                        Eigen::Matrix<double, 6, 6>* jtj = nullptr,
                        Eigen::Matrix<double, 6, 1>* jte = nullptr) {
  const Eigen::Vector3d s = sigma.array().exp();
  const Eigen::Matrix3d ra = rotation * axes;
  double cost = 0;
  if (jtj != nullptr) {
    jtj->setZero();
    jte->setZero();
  }
  for (Eigen::Index i = 0; i < u.rows(); ++i) {
    if (c.w[i] == 0) continue;
    const Eigen::Vector3d scaled = s.cwiseProduct(u.row(i).transpose());
    const Eigen::Vector3d mapped = ra * scaled;
    const Eigen::Vector3d r = mapped - c.q.row(i).transpose();
    cost += c.w[i] * r.squaredNorm();
    if (jtj == nullptr) continue;
    Eigen::Matrix<double, 3, 6> j;
    j.leftCols<3>() = -skew(mapped);              // d(exp([w]x) R x)/dw at w = 0
    j.rightCols<3>() = ra * scaled.asDiagonal();  // d/d sigma_k = R A e_k s_k u_k
    *jtj += c.w[i] * j.transpose() * j;
    *jte += c.w[i] * j.transpose() * r;
  }
  return cost;
}

struct AxisScaled {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d sigma;  // log of the scales
  int iterations = 0;
  bool converged = false;
};

AxisScaled fit_axis_scaled(const Centred& c, const Eigen::Matrix3d& axes, const Similarity& start,
                           const RigidFitOptions& options) {
  const Eigen::MatrixX3d u = c.p * axes;
  for (int k = 0; k < 3; ++k) {
    const double along = c.w.dot(u.col(k).cwiseAbs2());
    const double total = c.w.dot(c.p.rowwise().squaredNorm());
    if (!(along >= kCollinearVarianceRatio * total)) {
      throw InvalidInputError("rigid_fit: the source has no extent along scale axis " +
                              std::to_string(k) +
                              ", so its scale is undetermined; hint: use kSimilarity");
    }
  }
  AxisScaled out;
  out.rotation = start.rotation;
  out.sigma = Eigen::Vector3d::Constant(std::log(start.scale));
  Eigen::Matrix<double, 6, 6> jtj;
  Eigen::Matrix<double, 6, 1> jte;
  double cost = axis_scaled_cost(u, c, axes, out.rotation, out.sigma, &jtj, &jte);
  // Steps are measured against the parameters' size: rotation increments are
  // angles (radians), sigma are log scales; both are of order one.
  double damping = kInitialDamping;
  while (out.iterations < options.max_iterations) {
    if (cost == 0.0) {
      out.converged = true;
      break;
    }
    ++out.iterations;
    Eigen::Matrix<double, 6, 6> system = jtj;
    system.diagonal() += damping * jtj.diagonal().cwiseMax(kMinDamping);
    const Eigen::Matrix<double, 6, 1> step = system.ldlt().solve(-jte);
    if (step.norm() <= options.tolerance * (1.0 + out.sigma.norm())) {
      out.converged = true;
      break;
    }
    const Eigen::Vector3d w = step.head<3>();
    const Eigen::Matrix3d rotation =
        (w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                      : Eigen::Matrix3d::Identity()) *
        out.rotation;
    const Eigen::Vector3d sigma = out.sigma + step.tail<3>();
    Eigen::Matrix<double, 6, 6> candidate_jtj;
    Eigen::Matrix<double, 6, 1> candidate_jte;
    const double candidate =
        axis_scaled_cost(u, c, axes, rotation, sigma, &candidate_jtj, &candidate_jte);
    if (candidate < cost) {
      const double decrease = (cost - candidate) / cost;
      out.rotation = rotation;
      out.sigma = sigma;
      cost = candidate;
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
        out.converged = true;  // no descent left: a minimum up to rounding
        break;
      }
    }
  }
  return out;
}

Eigen::Matrix3d checked_axes(const Eigen::Matrix3d& axes) {
  if (!axes.allFinite() ||
      (axes.transpose() * axes - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() >
          kOrthonormalTolerance) {
    throw InvalidInputError("rigid_fit: scale_axes must be orthonormal columns");
  }
  return axes;
}

}  // namespace

RigidFitResult rigid_fit(const Eigen::MatrixX3d& source, const Eigen::MatrixX3d& target,
                         const Eigen::VectorXd& weights, const RigidFitOptions& options) {
  check_input(source, target, weights);
  if (options.max_iterations < 0) {
    throw InvalidInputError("rigid_fit: max_iterations must be >= 0, got " +
                            std::to_string(options.max_iterations));
  }
  const Centred c = centre(source, target, weights);
  const Similarity similarity = umeyama(c, options.model != TransformModel::kRigid);

  RigidFitResult out;
  Eigen::Matrix3d rotation = similarity.rotation;
  switch (options.model) {
    case TransformModel::kRigid:
      break;
    case TransformModel::kSimilarity:
      out.scale = similarity.scale;
      out.axis_scales.setConstant(similarity.scale);
      out.stretch = similarity.scale * Eigen::Matrix3d::Identity();
      break;
    case TransformModel::kAxisScaled: {
      const Eigen::Matrix3d axes = options.scale_axes ? checked_axes(*options.scale_axes)
                                                      : principal_axes(source, weights).axes;
      const AxisScaled fit = fit_axis_scaled(c, axes, similarity, options);
      rotation = fit.rotation;
      out.axis_scales = fit.sigma.array().exp();
      out.scale = std::exp(fit.sigma.mean());
      out.scale_axes = axes;
      out.stretch = axes * out.axis_scales.asDiagonal() * axes.transpose();
      out.iterations = fit.iterations;
      out.converged = fit.converged;
      break;
    }
  }
  out.rigid.linear() = rotation;
  out.rigid.translation() = c.mean_q - rotation * out.stretch * c.mean_p;
  out.transform = out.rigid * Eigen::Affine3d(out.stretch);

  const Eigen::MatrixX3d mapped = (source * out.transform.linear().transpose()).rowwise() +
                                  out.transform.translation().transpose();
  out.rms = std::sqrt(c.w.dot((mapped - target).rowwise().squaredNorm()));
  if (!out.transform.matrix().allFinite() || !std::isfinite(out.rms)) {
    throw SolverError("rigid_fit: the fit gave non-finite numbers");
  }
  return out;
}

RigidFitResult rigid_fit(const Eigen::MatrixX3d& source, const Eigen::MatrixX3d& target,
                         const RigidFitOptions& options) {
  return rigid_fit(source, target, Eigen::VectorXd(), options);
}

}  // namespace mmm::fit

#include "core/atlas/bone_registration.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/fit/rigid_fit.h"

namespace mmm::atlas {
namespace {

// Corresponding rows with weights, gathered for one least-squares step.
struct Pairs {
  std::vector<Eigen::Vector3d> source;
  std::vector<Eigen::Vector3d> target;
  std::vector<double> weight;
  int surface_pairs = 0;
  double surface_sq_sum = 0.0;
  double surface_sum = 0.0;
};

Eigen::MatrixX3d rows(const std::vector<Eigen::Vector3d>& points) {
  Eigen::MatrixX3d matrix(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    matrix.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  }
  return matrix;
}

Pairs gather(const Eigen::MatrixX3d& source, const mesh::AabbTree* target,
             const std::vector<RegistrationAnchor>& anchors, const Eigen::Affine3d& current,
             const RegistrationOptions& options) {
  Pairs pairs;
  if (target != nullptr && source.rows() > 0) {
    std::vector<Eigen::Vector3d> closest(static_cast<std::size_t>(source.rows()));
    std::vector<double> distance(closest.size());
    for (Eigen::Index i = 0; i < source.rows(); ++i) {
      const Eigen::Vector3d moved = current * Eigen::Vector3d(source.row(i).transpose());
      const mesh::AabbTree::ClosestPoint hit = target->closest_point(moved);
      closest[static_cast<std::size_t>(i)] = hit.point;
      distance[static_cast<std::size_t>(i)] = std::sqrt(hit.squared_distance);
    }
    std::vector<double> sorted = distance;
    std::nth_element(sorted.begin(),
                     sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    const double limit = std::max(options.trim_factor * median, options.min_trim_mm);
    for (std::size_t i = 0; i < closest.size(); ++i) {
      if (distance[i] > limit) continue;
      pairs.source.emplace_back(source.row(static_cast<Eigen::Index>(i)).transpose());
      pairs.target.push_back(closest[i]);
      pairs.weight.push_back(1.0);
      ++pairs.surface_pairs;
      pairs.surface_sq_sum += distance[i] * distance[i];
      pairs.surface_sum += distance[i];
    }
  }
  const double anchor_unit = std::max(1, pairs.surface_pairs);
  for (const RegistrationAnchor& anchor : anchors) {
    pairs.source.push_back(anchor.source);
    pairs.target.push_back(anchor.target);
    pairs.weight.push_back(anchor.weight * anchor_unit);
  }
  return pairs;
}

// Affine map minimising sum w |A p + t - q|^2 + mu |A - prior|_F^2 with
// mu = regularisation * (sum w) * (weighted spread of p)^2.
Eigen::Affine3d fit_regularised_affine(const Pairs& pairs, const Eigen::Matrix3d& prior,
                                       double regularisation) {
  double total = 0.0;
  Eigen::Vector3d p_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d q_mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < pairs.source.size(); ++i) {
    total += pairs.weight[i];
    p_mean += pairs.weight[i] * pairs.source[i];
    q_mean += pairs.weight[i] * pairs.target[i];
  }
  p_mean /= total;
  q_mean /= total;
  Eigen::Matrix3d ptp = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d qtp = Eigen::Matrix3d::Zero();
  double spread = 0.0;
  for (std::size_t i = 0; i < pairs.source.size(); ++i) {
    const Eigen::Vector3d p = pairs.source[i] - p_mean;
    const Eigen::Vector3d q = pairs.target[i] - q_mean;
    ptp += pairs.weight[i] * p * p.transpose();
    qtp += pairs.weight[i] * q * p.transpose();
    spread += pairs.weight[i] * p.squaredNorm();
  }
  const double mu = regularisation * spread;
  const Eigen::Matrix3d lhs = ptp + mu * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d rhs = qtp + mu * prior;
  Eigen::Affine3d map = Eigen::Affine3d::Identity();
  // A lhs = rhs, lhs symmetric positive definite.
  map.linear() = lhs.ldlt().solve(rhs.transpose()).transpose();
  map.translation() = q_mean - map.linear() * p_mean;
  return map;
}

void check_finite(const Eigen::MatrixX3d& source, const std::vector<RegistrationAnchor>& anchors) {
  if (!source.allFinite()) {
    throw InvalidInputError("bone registration: a source point is not finite");
  }
  for (const RegistrationAnchor& anchor : anchors) {
    if (!anchor.source.allFinite() || !anchor.target.allFinite() || !std::isfinite(anchor.weight) ||
        anchor.weight < 0) {
      throw InvalidInputError("bone registration: anchor '" + anchor.name +
                              "' has a non-finite point or a bad weight");
    }
  }
}

}  // namespace

Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& linear) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  if ((u * svd.matrixV().transpose()).determinant() < 0) u.col(2) *= -1;
  return u * svd.matrixV().transpose();
}

RegistrationResult register_points(const Eigen::MatrixX3d& source, const mesh::AabbTree* target,
                                   const std::vector<RegistrationAnchor>& anchors,
                                   const Eigen::Affine3d& start,
                                   const RegistrationOptions& options) {
  check_finite(source, anchors);
  // Work in the started frame: source points and anchor sources moved by
  // `start`, the fitted map composed with it at the end.
  Eigen::MatrixX3d moved(source.rows(), 3);
  for (Eigen::Index i = 0; i < source.rows(); ++i) {
    moved.row(i) = (start * Eigen::Vector3d(source.row(i).transpose())).transpose();
  }
  std::vector<RegistrationAnchor> started = anchors;
  for (RegistrationAnchor& anchor : started) anchor.source = start * anchor.source;

  Eigen::Affine3d current = Eigen::Affine3d::Identity();
  Pairs pairs;
  double previous_rms = std::numeric_limits<double>::infinity();
  const auto step = [&](bool affine, const Eigen::Matrix3d& prior) {
    pairs = gather(moved, target, started, current, options);
    if (pairs.source.size() < 3) {
      throw InvalidInputError(
          "bone registration: fewer than 3 correspondences (no target surface near the "
          "source and too few anchors)");
    }
    if (affine) {
      current = fit_regularised_affine(pairs, prior, options.affine_regularisation);
    } else {
      Eigen::VectorXd weights(static_cast<Eigen::Index>(pairs.weight.size()));
      for (std::size_t i = 0; i < pairs.weight.size(); ++i) {
        weights(static_cast<Eigen::Index>(i)) = pairs.weight[i];
      }
      fit::RigidFitOptions fit_options;
      fit_options.model =
          options.keep_scale ? fit::TransformModel::kRigid : fit::TransformModel::kSimilarity;
      current =
          fit::rigid_fit(rows(pairs.source), rows(pairs.target), weights, fit_options).transform;
    }
    const double rms =
        pairs.surface_pairs > 0 ? std::sqrt(pairs.surface_sq_sum / pairs.surface_pairs) : 0.0;
    const bool converged = std::abs(previous_rms - rms) < options.tolerance_mm;
    previous_rms = rms;
    return converged;
  };
  const int similarity_steps = target == nullptr ? 1 : options.similarity_iterations;
  for (int i = 0; i < similarity_steps; ++i) {
    if (step(false, Eigen::Matrix3d::Identity())) break;
  }
  if (options.anisotropic) {
    const Eigen::Matrix3d prior = current.linear();
    previous_rms = std::numeric_limits<double>::infinity();
    const int affine_steps = target == nullptr ? 1 : options.affine_iterations;
    for (int i = 0; i < affine_steps; ++i) {
      if (step(true, prior)) break;
    }
  }

  RegistrationResult result;
  result.map = current * start;
  result.scale = std::cbrt(std::abs(result.map.linear().determinant()));
  // Residuals of the final map (a last look-up of the pairs).
  pairs = gather(moved, target, started, current, options);
  result.pairs = pairs.surface_pairs;
  if (pairs.surface_pairs > 0) {
    result.rms_mm = std::sqrt(pairs.surface_sq_sum / pairs.surface_pairs);
    result.mean_distance_mm = pairs.surface_sum / pairs.surface_pairs;
  }
  for (const RegistrationAnchor& anchor : anchors) {
    result.anchor_residuals_mm.emplace_back(anchor.name,
                                            (result.map * anchor.source - anchor.target).norm());
  }
  return result;
}

}  // namespace mmm::atlas

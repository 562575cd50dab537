#pragma once
// Weighted least-squares registration of corresponding point pairs: the map T
// of a chosen family minimising sum_i w_i |T(p_i) - q_i|^2.
//
// Rigid and similarity, in closed form (Umeyama 1991, "Least-squares
// estimation of transformation parameters between two point patterns";
// Kabsch 1976 for the rotation):
//   centroids mu_p, mu_q (weighted); covariance H = sum w (q - mu_q)(p - mu_p)^T / W
//   H = U D V^T;  E = diag(1, 1, det(U V^T))      (no reflection)
//   R = U E V^T;  s = tr(D E) / var(p) (similarity) or 1;  t = mu_q - s R mu_p
//
// Axis-scaled, for one bone onto the same bone of another subject: people
// differ in proportions (a longer femur is not uniformly bigger), so the
// source is scaled by its own factor along each of three orthonormal axes A
// (by default its principal axes: length, width, depth) and then moved rigidly:
//   T(p) = R A diag(s) A^T p + t,  s > 0                   (9 parameters)
// This is the per-segment, per-axis scaling of OpenSim's Scale tool, with the
// axes taken from the bone's shape rather than from its body frame; it keeps
// no shear, so anatomical directions stay orthogonal. The translation follows
// from the centroids as above; (R, log s) are refined by Levenberg-Marquardt
// on the rotation manifold (R <- exp([w]x) R), starting from the similarity
// fit, so the scales stay positive and the rotation proper.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace mmm::fit {

// Family of maps fitted (shared with icp).
enum class TransformModel {
  kRigid,       // p -> R p + t                       (6 parameters)
  kSimilarity,  // p -> s R p + t, s > 0              (7)
  kAxisScaled,  // p -> R A diag(s) A^T p + t, s > 0  (9; icp: point-to-point only)
};

struct RigidFitOptions {
  TransformModel model = TransformModel::kRigid;
  // kAxisScaled only: columns are the orthonormal axes (source coordinates)
  // along which the source is scaled. Default: the principal axes of the
  // weighted source points (see principal_axes.h).
  std::optional<Eigen::Matrix3d> scale_axes;
  // kAxisScaled only: most Levenberg-Marquardt iterations (>= 0) after the
  // similarity start, and the convergence tolerance on the step (relative to
  // the parameters) and on the relative decrease of the cost.
  int max_iterations = 100;
  double tolerance = 1e-14;
};

struct RigidFitResult {
  // The fitted map, source -> target: transform = rigid * stretch, that is
  // p -> R (S p) + t.
  Eigen::Affine3d transform = Eigen::Affine3d::Identity();
  Eigen::Isometry3d rigid = Eigen::Isometry3d::Identity();  // R (proper), t (mm)
  // S, symmetric positive definite: I (kRigid), s I (kSimilarity),
  // A diag(axis_scales) A^T (kAxisScaled).
  Eigen::Matrix3d stretch = Eigen::Matrix3d::Identity();
  // s for kSimilarity, 1 for kRigid, the geometric mean of axis_scales
  // (volume ratio^(1/3)) for kAxisScaled.
  double scale = 1.0;
  // kAxisScaled: scale along each column of scale_axes; otherwise scale
  // repeated, with scale_axes the identity.
  Eigen::Vector3d axis_scales = Eigen::Vector3d::Ones();
  Eigen::Matrix3d scale_axes = Eigen::Matrix3d::Identity();
  // sqrt(sum w_i |T(p_i) - q_i|^2 / sum w_i), the weighted RMS residual (mm).
  double rms = 0;
  int iterations = 0;     // Levenberg-Marquardt iterations (kAxisScaled only)
  bool converged = true;  // kAxisScaled: tolerance reached within max_iterations
};

// Fits T with T(source_i) ~ target_i.
//   source, target  #P by 3 corresponding positions (mm), row i with row i
//   weights         #P weights >= 0 (0 drops a pair), or empty for all 1
// Throws InvalidInputError when the sizes differ, a coordinate or weight is
// not finite, a weight is negative, fewer than 3 pairs have positive weight,
// the weighted source or target points are collinear (or coincide) up to
// rounding (their variance across the line is below 1e-12 of that along it,
// which leaves the rotation about the line free), the scale_axes are not
// orthonormal, or (kAxisScaled) the source has no extent along a scale axis.
// Throws SolverError when the result is not finite.
RigidFitResult rigid_fit(const Eigen::MatrixX3d& source, const Eigen::MatrixX3d& target,
                         const Eigen::VectorXd& weights, const RigidFitOptions& options = {});

// Same with all weights 1.
RigidFitResult rigid_fit(const Eigen::MatrixX3d& source, const Eigen::MatrixX3d& target,
                         const RigidFitOptions& options = {});

}  // namespace mmm::fit

#pragma once
// Iterative closest point: moves a point set (source) onto a triangle mesh
// (target) by alternating correspondence and fit, each iteration lowering
//   E(T) = sum_{i ranked} w_i min(d_i, max_distance)^2 + sum_j v_j |T(a_j) - b_j|^2
// where d_i is the distance of T(p_i) to the target and the ranked points are
// the closest (1 - trim_fraction) of those of positive weight (trimmed ICP,
// Chetverikov et al. 2002; pairs beyond max_distance count as max_distance,
// a truncated quadratic). Landmark pairs (a_j on the source, b_j on the
// target, weight v_j) enter every fit, so that anatomical landmarks anchor
// directions the surface leaves free (a sphere's rotation, a cylinder's spin)
// and keep ICP out of a wrong local minimum.
//
//   T = options.initial
//   repeat up to max_iterations times:
//     y_i = T(p_i); q_i = closest point of the target, n_i its face normal
//     kept = ranked pairs with d_i <= max_distance
//     point-to-point: T = rigid_fit(kept pairs + landmark pairs) in closed
//       form (Besl & McKay 1992; Umeyama 1991)
//     point-to-plane: minimise sum_kept w (n_i.(T'(y_i) - q_i))^2 + landmark
//       terms over a small update T' = exp(sigma) R(w) about the centroid
//       plus a translation, linearised in (w, t, sigma) (Chen & Medioni 1992;
//       Low 2004); halve the step until E drops (far from the solution the
//       tangent planes mislead and the full step can overshoot); T = T' T
//     stop when sqrt(E / W) changed by less than rms_tolerance, W being the
//       weight of the ranked points plus the landmarks' (or when no halving
//       of a point-to-plane step lowers E)
// Point-to-plane converges in far fewer iterations on smooth surfaces, and
// slides along them; point-to-point converges linearly.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <optional>
#include <vector>

#include "core/fit/rigid_fit.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::fit {

// A source point that must land on a known target point.
struct LandmarkPair {
  Eigen::Vector3d source = Eigen::Vector3d::Zero();  // source coordinates (mm)
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // target coordinates (mm)
  // >= 0; the pair counts like that many surface points of weight 1.
  double weight = 1.0;
};

struct IcpOptions {
  enum class Metric {
    kPointToPoint,  // distance to the closest point
    kPointToPlane,  // distance to the tangent plane at the closest point
  };
  Metric metric = Metric::kPointToPlane;
  // kRigid or kSimilarity; kAxisScaled with kPointToPoint only (its scale axes
  // are fixed for the whole run: scale_axes, or the principal axes of the
  // weighted source points).
  TransformModel model = TransformModel::kRigid;
  std::optional<Eigen::Matrix3d> scale_axes;
  // Starting transform, source -> target. For kRigid a rotation plus a
  // translation, for kSimilarity a scaled rotation (scale > 0) plus a
  // translation, for kAxisScaled any affine map with a positive determinant.
  Eigen::Affine3d initial = Eigen::Affine3d::Identity();
  // Most fits (>= 0); 0 only measures the initial transform.
  int max_iterations = 100;
  // Converged when sqrt(E / W) (see above) changes by less than this between
  // iterations (mm).
  double rms_tolerance = 1e-6;
  // Fraction of the weighted source points left out each iteration, the
  // farthest first, in [0, 1): the expected share of source points with no
  // counterpart on the target (a partial scan, osteophytes, a segmentation
  // leak).
  double trim_fraction = 0.0;
  // Pairs farther apart than this are left out of the fit (mm, > 0); in E
  // they count as this distance.
  double max_distance = std::numeric_limits<double>::infinity();
};

struct IcpResult {
  // Source -> target: transform = rigid * stretch (see RigidFitResult).
  Eigen::Affine3d transform = Eigen::Affine3d::Identity();
  Eigen::Isometry3d rigid = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d stretch = Eigen::Matrix3d::Identity();
  double scale = 1.0;      // uniform scale; geometric mean of the axis scales for kAxisScaled
  int iterations = 0;      // fits performed (accepted steps)
  bool converged = false;  // stopped by rms_tolerance or an exact fit, not max_iterations
  // At the final transform: weighted RMS distance to the target surface of
  // the pairs kept (mm), and weighted RMS landmark residual (mm, 0 without
  // landmarks).
  double rms = 0;
  double landmark_rms = 0;
  // #P distance of every transformed source point to the target surface at
  // the final transform (mm), and whether it is kept as a pair there (ranked
  // and within max_distance).
  Eigen::VectorXd distances;
  Eigen::Array<bool, Eigen::Dynamic, 1> kept;
};

// Registers `source` onto the surface held by `target`.
//   source     #P by 3 positions (mm)
//   weights    #P weights >= 0 (0 leaves a point out), or empty for all 1
//   target     AABB tree of the target mesh (build it once, reuse it)
//   landmarks  anchoring pairs, used in every iteration
// Throws InvalidInputError when a coordinate, weight or landmark is not finite,
// a weight is negative, the weight count is not #P, an option is out of range,
// kAxisScaled is asked with kPointToPlane, or `initial` is not of the model's
// form. Throws SolverError when an iteration is left with too few pairs to fit
// (fewer than 3 with landmarks counted; hint: raise max_distance or lower
// trim_fraction) or the linearised fit is not finite.
IcpResult icp(const Eigen::MatrixX3d& source, const Eigen::VectorXd& weights,
              const mesh::AabbTree& target, const std::vector<LandmarkPair>& landmarks,
              const IcpOptions& options = {});

// Same with all weights 1 and no landmarks.
IcpResult icp(const Eigen::MatrixX3d& source, const mesh::AabbTree& target,
              const IcpOptions& options = {});

}  // namespace mmm::fit

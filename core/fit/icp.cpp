#include "core/fit/icp.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>

#include "core/errors.h"
#include "core/fit/principal_axes.h"

namespace mmm::fit {
namespace {

// How far the linear part of `initial` may be from the model's form (max entry
// of |L^T L / s^2 - I|): generous for transforms written out by hand or read
// back from text with ~7 digits.
constexpr double kFormTolerance = 1e-6;

// Tikhonov term added to the column-scaled point-to-plane normal equations
// (whose diagonal is then 1): directions the data leave free (a sphere's
// rotation) get a zero update instead of noise.
constexpr double kRegularisation = 1e-10;

// Most halvings of a point-to-plane step that raises the objective: 2^-30 of
// a step is below rounding of the transform.
constexpr int kMaxHalvings = 30;

using Rows = Eigen::Array<bool, Eigen::Dynamic, 1>;

// Unit outward normals of the faces (zero for a degenerate face).
Eigen::MatrixX3d face_normals(const mesh::IndexedMesh& m) {
  Eigen::MatrixX3d normals(m.F.rows(), 3);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)).transpose();
    const Eigen::Vector3d b = m.V.row(m.F(f, 1)).transpose();
    const Eigen::Vector3d c = m.V.row(m.F(f, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double length = n.norm();
    normals.row(f) =
        length > 0 ? Eigen::RowVector3d(n.transpose() / length) : Eigen::RowVector3d::Zero();
  }
  return normals;
}

// Pairs of the current iteration and the objective that measures it.
struct Correspondences {
  Eigen::MatrixX3d moved;    // T(p_i)
  Eigen::MatrixX3d closest;  // q_i
  Eigen::MatrixX3d normals;  // n_i
  Eigen::VectorXd distances;
  Rows kept;
  // E = sum over the ranked points of w min(d, max_distance)^2 plus the
  // landmark terms, and its (constant) weight W: the objective that every
  // iteration lowers (see icp.h).
  double objective = 0;
  double objective_weight = 0;
  double surface_sum = 0;  // sum over kept of w d^2
  double surface_weight = 0;
  double landmark_sum = 0;  // sum of v |T(a) - b|^2
  double landmark_weight = 0;

  [[nodiscard]] double rms() const {
    return objective_weight > 0 ? std::sqrt(objective / objective_weight) : 0.0;
  }
  [[nodiscard]] double surface_rms() const {
    return surface_weight > 0 ? std::sqrt(surface_sum / surface_weight) : 0.0;
  }
  [[nodiscard]] double landmark_rms() const {
    return landmark_weight > 0 ? std::sqrt(landmark_sum / landmark_weight) : 0.0;
  }
};

Correspondences correspond(const Eigen::MatrixX3d& source, const Eigen::VectorXd& weights,
                           const mesh::AabbTree& target, const Eigen::MatrixX3d& target_normals,
                           const std::vector<LandmarkPair>& landmarks, const Eigen::Affine3d& t,
                           const IcpOptions& options) {
  const Eigen::Index n = source.rows();
  Correspondences c;
  c.moved = (source * t.linear().transpose()).rowwise() + t.translation().transpose();
  c.closest.resize(n, 3);
  c.normals.resize(n, 3);
  c.distances.resize(n);
  c.kept = Rows::Constant(n, false);
  std::vector<Eigen::Index> ranked;  // points of positive weight
  ranked.reserve(static_cast<size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const mesh::AabbTree::ClosestPoint hit = target.closest_point(c.moved.row(i).transpose());
    c.closest.row(i) = hit.point.transpose();
    c.normals.row(i) = target_normals.row(hit.face);
    c.distances[i] = std::sqrt(hit.squared_distance);
    if (weights[i] > 0) ranked.push_back(i);
  }
  // Trimming: the closest (1 - trim_fraction) of the weighted points take
  // part; ties broken by index so that the choice is deterministic.
  const auto drop =
      static_cast<size_t>(std::floor(options.trim_fraction * static_cast<double>(ranked.size())));
  const size_t keep = ranked.size() - drop;
  if (drop > 0) {
    std::nth_element(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep),
                     ranked.end(), [&](Eigen::Index a, Eigen::Index b) {
                       return c.distances[a] < c.distances[b] ||
                              (c.distances[a] == c.distances[b] && a < b);
                     });
  }
  for (size_t k = 0; k < keep; ++k) {
    const Eigen::Index i = ranked[k];
    const double d = c.distances[i];
    c.objective += weights[i] * std::pow(std::min(d, options.max_distance), 2);
    c.objective_weight += weights[i];
    if (d <= options.max_distance) {
      c.kept[i] = true;
      c.surface_sum += weights[i] * d * d;
      c.surface_weight += weights[i];
    }
  }
  for (const LandmarkPair& l : landmarks) {
    c.landmark_sum += l.weight * (t * l.source - l.target).squaredNorm();
    c.landmark_weight += l.weight;
  }
  c.objective += c.landmark_sum;
  c.objective_weight += c.landmark_weight;
  return c;
}

Eigen::Index count_pairs(const Correspondences& c, const std::vector<LandmarkPair>& landmarks) {
  Eigen::Index count = c.kept.count();
  for (const LandmarkPair& l : landmarks) count += l.weight > 0 ? 1 : 0;
  return count;
}

// Point-to-point: the closed-form fit of the kept pairs and the landmarks,
// from the original source positions.
Eigen::Affine3d fit_point_to_point(const Eigen::MatrixX3d& source, const Eigen::VectorXd& weights,
                                   const std::vector<LandmarkPair>& landmarks,
                                   const Correspondences& c, const RigidFitOptions& fit_options) {
  const Eigen::Index rows = count_pairs(c, landmarks);
  Eigen::MatrixX3d from(rows, 3);
  Eigen::MatrixX3d to(rows, 3);
  Eigen::VectorXd w(rows);
  Eigen::Index r = 0;
  for (Eigen::Index i = 0; i < source.rows(); ++i) {
    if (!c.kept[i]) continue;
    from.row(r) = source.row(i);
    to.row(r) = c.closest.row(i);
    w[r++] = weights[i];
  }
  for (const LandmarkPair& l : landmarks) {
    if (!(l.weight > 0)) continue;
    from.row(r) = l.source.transpose();
    to.row(r) = l.target.transpose();
    w[r++] = l.weight;
  }
  return rigid_fit(from, to, w, fit_options).transform;
}

// A point-to-plane step: rotation vector w, translation t and log scale sigma
// (0 for kRigid) about `centre`.
struct PlaneStep {
  Eigen::Vector3d centre;
  Eigen::Vector3d rotation;
  Eigen::Vector3d translation;
  double log_scale = 0;

  // The update x -> centre + exp(a sigma) R(a w) (x - centre) + a t, to
  // compose on the left of the current transform, for a step fraction a.
  [[nodiscard]] Eigen::Affine3d update(double fraction) const {
    const Eigen::Vector3d w = fraction * rotation;
    const Eigen::Matrix3d r = w.norm() > 0
                                  ? Eigen::AngleAxisd(w.norm(), w / w.norm()).toRotationMatrix()
                                  : Eigen::Matrix3d::Identity();
    Eigen::Affine3d u = Eigen::Affine3d::Identity();
    u.linear() = std::exp(fraction * log_scale) * r;
    u.translation() = centre + fraction * translation - u.linear() * centre;
    return u;
  }
};

// Point-to-plane: one linearised least-squares step.
PlaneStep fit_point_to_plane(const Eigen::VectorXd& weights,
                             const std::vector<LandmarkPair>& landmarks, const Correspondences& c,
                             const Eigen::Affine3d& current, bool with_scale) {
  // Linearise about the weighted centroid of everything that pulls, so that
  // rotation and scale do not couple with translation through a far origin.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double total = 0;
  for (Eigen::Index i = 0; i < c.moved.rows(); ++i) {
    if (!c.kept[i]) continue;
    centre += weights[i] * c.moved.row(i).transpose();
    total += weights[i];
  }
  for (const LandmarkPair& l : landmarks) {
    centre += l.weight * (current * l.source);
    total += l.weight;
  }
  centre /= total;

  // Unknowns x = (w, t, sigma): rotation vector, translation, log scale.
  const int dim = with_scale ? 7 : 6;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(dim, dim);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(dim);
  Eigen::VectorXd row(dim);
  for (Eigen::Index i = 0; i < c.moved.rows(); ++i) {
    if (!c.kept[i]) continue;
    const Eigen::Vector3d y = c.moved.row(i).transpose();
    const Eigen::Vector3d n = c.normals.row(i).transpose();
    const Eigen::Vector3d d = y - centre;
    // n.(y' - q) with y' = centre + (1 + sigma)(d + w x d) + t, to first order.
    row.head<3>() = d.cross(n);
    row.segment<3>(3) = n;
    if (with_scale) row[6] = n.dot(d);
    const double residual = n.dot(y - c.closest.row(i).transpose());
    a.selfadjointView<Eigen::Lower>().rankUpdate(row, weights[i]);
    b -= weights[i] * residual * row;
  }
  Eigen::MatrixXd j(3, dim);
  for (const LandmarkPair& l : landmarks) {
    const Eigen::Vector3d y = current * l.source;
    const Eigen::Vector3d d = y - centre;
    j.leftCols<3>() << 0, d.z(), -d.y(), -d.z(), 0, d.x(), d.y(), -d.x(), 0;  // -[d]x
    j.middleCols<3>(3).setIdentity();
    if (with_scale) j.col(6) = d;
    a.selfadjointView<Eigen::Lower>().rankUpdate(j.transpose(), l.weight);
    b -= l.weight * j.transpose() * (y - l.target);
  }
  a = a.selfadjointView<Eigen::Lower>();
  // Jacobi scaling: rotation and scale columns carry lengths (mm), the
  // translation columns unit normals; scaled, the diagonal is 1.
  const Eigen::VectorXd s =
      a.diagonal().unaryExpr([](double v) { return v > 0 ? 1.0 / std::sqrt(v) : 1.0; });
  Eigen::MatrixXd scaled = s.asDiagonal() * a * s.asDiagonal();
  scaled.diagonal().array() += kRegularisation;
  const Eigen::VectorXd x = s.cwiseProduct(scaled.ldlt().solve(s.cwiseProduct(b)));
  if (!x.allFinite()) throw SolverError("icp: the point-to-plane step is not finite");

  PlaneStep step;
  step.centre = centre;
  step.rotation = x.head<3>();
  step.translation = x.segment<3>(3);
  step.log_scale = with_scale ? x[6] : 0.0;
  return step;
}

void check_input(const Eigen::MatrixX3d& source, const Eigen::VectorXd& weights,
                 const std::vector<LandmarkPair>& landmarks, const IcpOptions& options) {
  const Eigen::Index n = source.rows();
  if (weights.size() != n) {
    throw InvalidInputError("icp: " + std::to_string(weights.size()) + " weights for " +
                            std::to_string(n) + " source points");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!source.row(i).allFinite()) {
      throw InvalidInputError("icp: source point " + std::to_string(i) + " is not finite");
    }
    if (!(weights[i] >= 0 && std::isfinite(weights[i]))) {
      throw InvalidInputError("icp: weight " + std::to_string(i) + " is " +
                              std::to_string(weights[i]) + ", expected finite and >= 0");
    }
  }
  for (size_t j = 0; j < landmarks.size(); ++j) {
    const LandmarkPair& l = landmarks[j];
    if (!l.source.allFinite() || !l.target.allFinite() || !std::isfinite(l.weight) ||
        l.weight < 0) {
      throw InvalidInputError("icp: landmark pair " + std::to_string(j) +
                              " has a non-finite position or a negative or non-finite weight");
    }
  }
  if (options.max_iterations < 0) {
    throw InvalidInputError("icp: max_iterations must be >= 0, got " +
                            std::to_string(options.max_iterations));
  }
  if (!(options.rms_tolerance >= 0)) {
    throw InvalidInputError("icp: rms_tolerance must be >= 0, got " +
                            std::to_string(options.rms_tolerance));
  }
  if (!(options.trim_fraction >= 0 && options.trim_fraction < 1)) {
    throw InvalidInputError("icp: trim_fraction must be in [0, 1), got " +
                            std::to_string(options.trim_fraction));
  }
  if (!(options.max_distance > 0)) {
    throw InvalidInputError("icp: max_distance must be > 0 mm, got " +
                            std::to_string(options.max_distance));
  }
  if (options.model == TransformModel::kAxisScaled &&
      options.metric == IcpOptions::Metric::kPointToPlane) {
    throw InvalidInputError(
        "icp: the kAxisScaled model needs the kPointToPoint metric; hint: register with "
        "kSimilarity and kPointToPlane first, then refine with kAxisScaled and kPointToPoint");
  }
  const Eigen::Matrix3d linear = options.initial.linear();
  if (!options.initial.matrix().allFinite() || !(linear.determinant() > 0)) {
    throw InvalidInputError(
        "icp: the initial transform is not finite, not invertible or a reflection");
  }
  if (options.model != TransformModel::kAxisScaled) {
    const double det = linear.determinant();
    const double scale = std::cbrt(det);
    const double error =
        (linear.transpose() * linear / (scale * scale) - Eigen::Matrix3d::Identity())
            .cwiseAbs()
            .maxCoeff();
    const bool rigid_ok = options.model != TransformModel::kRigid || std::abs(scale - 1) <= 1e-6;
    if (det <= 0 || error > kFormTolerance || !rigid_ok) {
      throw InvalidInputError(std::string("icp: the initial transform is not a ") +
                              (options.model == TransformModel::kRigid
                                   ? "rotation plus translation"
                                   : "scaled rotation plus translation") +
                              " (no reflection, shear or, for kRigid, scale)");
    }
  }
}

}  // namespace

IcpResult icp(const Eigen::MatrixX3d& source, const Eigen::VectorXd& weights,
              const mesh::AabbTree& target, const std::vector<LandmarkPair>& landmarks,
              const IcpOptions& options) {
  const Eigen::VectorXd w =
      weights.size() == 0 ? Eigen::VectorXd(Eigen::VectorXd::Ones(source.rows())) : weights;
  check_input(source, w, landmarks, options);
  const Eigen::MatrixX3d target_normals = face_normals(target.mesh());
  RigidFitOptions fit_options;
  fit_options.model = options.model;
  if (options.model == TransformModel::kAxisScaled) {
    // Fixed for the whole run, so that every iteration scales along the same
    // axes.
    fit_options.scale_axes =
        options.scale_axes ? *options.scale_axes : principal_axes(source, w).axes;
  }

  IcpResult out;
  Eigen::Affine3d t = options.initial;
  Correspondences c = correspond(source, w, target, target_normals, landmarks, t, options);
  while (out.iterations < options.max_iterations) {
    if (count_pairs(c, landmarks) < 3) {
      throw SolverError("icp: iteration " + std::to_string(out.iterations + 1) + " has only " +
                        std::to_string(count_pairs(c, landmarks)) +
                        " pairs (3 needed); hint: raise max_distance or lower trim_fraction");
    }
    if (c.objective == 0) {
      out.converged = true;  // an exact fit
      break;
    }
    Eigen::Affine3d next;
    Correspondences next_c;
    try {
      if (options.metric == IcpOptions::Metric::kPointToPoint) {
        // The closed-form fit cannot raise the objective (Besl & McKay 1992).
        next = fit_point_to_point(source, w, landmarks, c, fit_options);
        next_c = correspond(source, w, target, target_normals, landmarks, next, options);
      } else {
        // The linearised step can overshoot far from the solution (the
        // tangent planes are poor approximations there): halve it until the
        // objective drops.
        const PlaneStep step =
            fit_point_to_plane(w, landmarks, c, t, options.model == TransformModel::kSimilarity);
        double fraction = 1.0;
        for (int halving = 0; halving <= kMaxHalvings; ++halving, fraction /= 2) {
          next = step.update(fraction) * t;
          next_c = correspond(source, w, target, target_normals, landmarks, next, options);
          if (next_c.objective < c.objective) break;
        }
        if (!(next_c.objective < c.objective)) {
          out.converged = true;  // no descent left: a minimum up to rounding
          break;
        }
      }
    } catch (const InvalidInputError& e) {
      throw SolverError("icp: iteration " + std::to_string(out.iterations + 1) +
                        ": the pairs do not determine the transform: " + e.what());
    }
    ++out.iterations;
    const double change = std::abs(c.rms() - next_c.rms());
    t = next;
    c = std::move(next_c);
    if (change < options.rms_tolerance) {
      out.converged = true;
      break;
    }
  }

  // transform = rigid * stretch by the polar decomposition L = R S.
  out.transform = t;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(t.linear(),
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  out.stretch = svd.matrixV() * svd.singularValues().asDiagonal() * svd.matrixV().transpose();
  out.scale = std::cbrt(svd.singularValues().prod());
  out.rigid.linear() = rotation;
  out.rigid.translation() = t.translation();
  out.rms = c.surface_rms();
  out.landmark_rms = c.landmark_rms();
  out.distances = c.distances;
  out.kept = c.kept;
  if (!out.transform.matrix().allFinite()) throw SolverError("icp: the transform is not finite");
  return out;
}

IcpResult icp(const Eigen::MatrixX3d& source, const mesh::AabbTree& target,
              const IcpOptions& options) {
  return icp(source, Eigen::VectorXd(), target, {}, options);
}

}  // namespace mmm::fit

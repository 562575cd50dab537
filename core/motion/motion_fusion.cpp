#include "core/motion/motion_fusion.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <set>

#include "core/errors.h"
#include "core/fit/rigid_fit.h"

namespace mmm::motion {
namespace {

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Rows of the trial in [start, end] (half a frame of slack at both ends).
std::vector<int> frames_in_range(const opensim::MarkerTrajectories& trial,
                                 const MotionFusionOptions& options) {
  const double slack = trial.data_rate > 0 ? 0.5 / trial.data_rate : 1e-9;
  const double start = options.start_time.value_or(-1e300) - slack;
  const double end = options.end_time.value_or(1e300) + slack;
  std::vector<int> frames;
  for (Eigen::Index f = 0; f < trial.num_frames(); ++f) {
    if (trial.times(f) >= start && trial.times(f) <= end) frames.push_back(static_cast<int>(f));
  }
  if (frames.empty()) {
    throw InvalidInputError(
        trial.source.string() + ": no frame between " +
        std::to_string(options.start_time.value_or(trial.times(0))) + " s and " +
        std::to_string(options.end_time.value_or(trial.times(trial.num_frames() - 1))) +
        " s (the trial spans " + std::to_string(trial.times(0)) + " to " +
        std::to_string(trial.times(trial.num_frames() - 1)) + " s)");
  }
  return frames;
}

// The tracked markers of one trial row, #setup.markers by 3 (mm, NaN missing).
Eigen::MatrixX3d targets_of(const opensim::MarkerTrajectories& trial, const TrackingSetup& setup,
                            int frame) {
  Eigen::MatrixX3d targets(static_cast<Eigen::Index>(setup.markers.size()), 3);
  for (std::size_t i = 0; i < setup.markers.size(); ++i) {
    targets.row(static_cast<Eigen::Index>(i)) =
        trial.unit_to_mm * trial.position(frame, setup.markers[i].trial).transpose();
  }
  return targets;
}

struct FreeBody {
  bool registered = false;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  double rms_mm = 0.0;
};

// Kabsch of each body's present markers (>= 3, not collinear).
std::vector<FreeBody> register_bodies(const Skeleton& skeleton, const TrackingSetup& setup,
                                      const Eigen::MatrixX3d& targets) {
  std::vector<FreeBody> bodies(skeleton.bodies.size());
  for (std::size_t b = 0; b < skeleton.bodies.size(); ++b) {
    std::vector<Eigen::Index> rows;
    for (std::size_t i = 0; i < setup.markers.size(); ++i) {
      const SkeletonMarker& marker =
          skeleton.markers[static_cast<std::size_t>(setup.markers[i].model)];
      if (marker.body == static_cast<int>(b) &&
          targets.row(static_cast<Eigen::Index>(i)).allFinite()) {
        rows.push_back(static_cast<Eigen::Index>(i));
      }
    }
    if (rows.size() < 3) continue;
    const auto count = static_cast<Eigen::Index>(rows.size());
    Eigen::MatrixX3d source(count, 3);
    Eigen::MatrixX3d target(count, 3);
    Eigen::VectorXd weights(count);
    for (Eigen::Index k = 0; k < count; ++k) {
      const BoundMarker& bound =
          setup.markers[static_cast<std::size_t>(rows[static_cast<std::size_t>(k)])];
      source.row(k) = skeleton.markers[static_cast<std::size_t>(bound.model)].local.transpose();
      target.row(k) = targets.row(rows[static_cast<std::size_t>(k)]);
      weights(k) = bound.weight;
    }
    try {
      const fit::RigidFitResult fit = fit::rigid_fit(source, target, weights);
      bodies[b] = {true, fit.rigid, fit.rms};
    } catch (const InvalidInputError&) {
      // Collinear markers in this frame: the body is not registered.
    }
  }
  return bodies;
}

// Root coordinates that put the root body at `target` (body -> world):
// Gauss-Newton on four points spanning the body from several starts of the
// root's rotation coordinates (the walking direction may be anything).
Eigen::VectorXd root_start(const Skeleton& skeleton, const Eigen::Isometry3d& target,
                           const Eigen::Vector3d& centre_local) {
  Eigen::VectorXd q = skeleton.default_coordinates();
  std::vector<int> free;
  std::vector<int> rotations;
  for (const SkeletonAxis& axis : skeleton.bodies.front().axes) {
    if (axis.coordinate < 0 || std::find(free.begin(), free.end(), axis.coordinate) != free.end()) {
      continue;
    }
    free.push_back(axis.coordinate);
    if (axis.rotation) rotations.push_back(axis.coordinate);
  }
  if (free.empty()) return q;
  const std::vector<Eigen::Vector3d> points = {centre_local,
                                               centre_local + 100.0 * Eigen::Vector3d::UnitX(),
                                               centre_local + 100.0 * Eigen::Vector3d::UnitY(),
                                               centre_local + 100.0 * Eigen::Vector3d::UnitZ()};
  SkeletonPose pose(skeleton);
  const auto cost_and_step = [&](const Eigen::VectorXd& at, Eigen::VectorXd* step) {
    pose.set(at);
    Eigen::VectorXd r(12);
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(12, skeleton.num_coordinates());
    for (std::size_t k = 0; k < points.size(); ++k) {
      const Eigen::Vector3d x = pose.point(0, points[k]);
      r.segment<3>(3 * static_cast<Eigen::Index>(k)) = x - target * points[k];
      pose.add_point_jacobian(0, x, 1.0, jacobian, 3 * static_cast<Eigen::Index>(k));
    }
    if (step != nullptr) {
      Eigen::MatrixXd j(12, static_cast<Eigen::Index>(free.size()));
      for (std::size_t c = 0; c < free.size(); ++c) {
        j.col(static_cast<Eigen::Index>(c)) = jacobian.col(free[c]);
      }
      const auto n = static_cast<Eigen::Index>(free.size());
      *step = (j.transpose() * j + 1e-6 * Eigen::MatrixXd::Identity(n, n))
                  .ldlt()
                  .solve(-j.transpose() * r);
    }
    return r.squaredNorm();
  };
  const std::vector<double> angles = {0.0, std::numbers::pi / 2, std::numbers::pi,
                                      -std::numbers::pi / 2};
  const auto starts = static_cast<std::size_t>(std::pow(4, rotations.size()));
  Eigen::VectorXd best = q;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < starts; ++s) {
    Eigen::VectorXd at = q;
    std::size_t code = s;
    for (const int c : rotations) {
      at(c) = angles[code % 4];
      code /= 4;
    }
    double cost = cost_and_step(at, nullptr);
    for (int iteration = 0; iteration < 50; ++iteration) {
      Eigen::VectorXd step;
      cost_and_step(at, &step);
      double scale = 1.0;
      bool improved = false;
      for (int halving = 0; halving < 20 && !improved; ++halving, scale *= 0.5) {
        Eigen::VectorXd trial = at;
        for (std::size_t c = 0; c < free.size(); ++c) {
          trial(free[c]) += scale * step(static_cast<Eigen::Index>(c));
        }
        const double trial_cost = cost_and_step(trial, nullptr);
        if (trial_cost < cost) {
          improved = true;
          at = trial;
          cost = trial_cost;
        }
      }
      if (!improved || step.norm() < 1e-12) break;
    }
    // Euler-type angles reach one orientation two ways ((a, b, c) and
    // (a + pi, pi - b, c + pi) for gait2392's pelvis): of equally good
    // answers keep the one nearest the defaults, wrapped into (-pi, pi].
    for (const int c : rotations) at(c) = std::remainder(at(c), 2.0 * std::numbers::pi);
    const double tie = 1e-9 * (1.0 + best_cost);
    if (cost < best_cost - tie ||
        (cost <= best_cost + tie && (at - q).squaredNorm() < (best - q).squaredNorm())) {
      best_cost = std::min(cost, best_cost);
      best = at;
    }
  }
  return best;
}

}  // namespace

std::optional<int> FusedMotion::coordinate_index(std::string_view name) const {
  for (std::size_t i = 0; i < coordinate_names.size(); ++i) {
    if (coordinate_names[i] == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

double FusedMotion::overall_rms_mm() const {
  double squares = 0.0;
  Eigen::Index count = 0;
  for (Eigen::Index f = 0; f < marker_errors.rows(); ++f) {
    for (Eigen::Index m = 0; m < marker_errors.cols(); ++m) {
      if (std::isfinite(marker_errors(f, m))) {
        squares += marker_errors(f, m) * marker_errors(f, m);
        ++count;
      }
    }
  }
  return count > 0 ? std::sqrt(squares / static_cast<double>(count)) : std::nan("");
}

std::vector<std::vector<Eigen::Isometry3d>> poses_of(const Skeleton& skeleton,
                                                     const Eigen::MatrixXd& coordinates) {
  SkeletonPose pose(skeleton);
  std::vector<std::vector<Eigen::Isometry3d>> poses;
  poses.reserve(static_cast<std::size_t>(coordinates.rows()));
  for (Eigen::Index f = 0; f < coordinates.rows(); ++f) {
    pose.set(coordinates.row(f).transpose());
    poses.push_back(pose.body_poses());
  }
  return poses;
}

FusedMotion fuse_motion(const Skeleton& skeleton, const opensim::MarkerTrajectories& trial,
                        const MarkerMapping& mapping, const MotionFusionOptions& options) {
  FusedMotion motion;
  motion.setup = bind_tracking(skeleton, mapping, trial.marker_names);
  motion.filter = options.filter.mode;
  const TrackingSetup& setup = motion.setup;
  const std::vector<int> frames = frames_in_range(trial, options);
  const auto count = static_cast<Eigen::Index>(frames.size());
  const int n = skeleton.num_coordinates();
  for (const SkeletonCoordinate& c : skeleton.coordinates) {
    motion.coordinate_names.push_back(c.name);
    motion.coordinate_units.push_back(c.unit);
  }
  for (const SkeletonBody& b : skeleton.bodies) motion.body_names.push_back(b.name);
  for (const BoundMarker& m : setup.markers) motion.marker_names.push_back(m.name);
  motion.trial_frames = frames;
  motion.times.resize(count);
  std::vector<Eigen::MatrixX3d> targets;
  std::vector<std::vector<FreeBody>> free_bodies;
  targets.reserve(frames.size());
  free_bodies.reserve(frames.size());
  for (Eigen::Index k = 0; k < count; ++k) {
    const int frame = frames[static_cast<std::size_t>(k)];
    motion.times(k) = trial.times(frame);
    targets.push_back(targets_of(trial, setup, frame));
    free_bodies.push_back(register_bodies(skeleton, setup, targets.back()));
  }

  // Start: the root's free-body pose in the first frame that has one.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  int on_root = 0;
  for (const BoundMarker& bound : setup.markers) {
    const SkeletonMarker& marker = skeleton.markers[static_cast<std::size_t>(bound.model)];
    if (marker.body == 0) {
      centre += marker.local;
      ++on_root;
    }
  }
  if (on_root > 0) centre /= on_root;
  Eigen::VectorXd q_start = skeleton.default_coordinates();
  bool placed = false;
  for (Eigen::Index k = 0; k < count && !placed; ++k) {
    const FreeBody& root = free_bodies[static_cast<std::size_t>(k)].front();
    if (!root.registered) continue;
    q_start = root_start(skeleton, root.pose, centre);
    placed = true;
  }
  if (!placed) {
    throw InvalidInputError(trial.source.string() +
                            ": no frame in the range has 3 of the root "
                            "body's tracked markers (" +
                            skeleton.bodies.front().name +
                            "); its pose cannot be started (check the marker mapping)");
  }

  ChainFitter fitter(skeleton, setup, options.fit);
  std::optional<MotionFilter> filter;
  if (options.filter.mode != FilterMode::kNone) filter.emplace(skeleton, options.filter);
  motion.coordinates.resize(count, n);
  motion.iterations.resize(count);
  motion.fit_seconds.resize(count);
  Eigen::VectorXd previous = q_start;
  int unconverged = 0;
  for (Eigen::Index k = 0; k < count; ++k) {
    const auto& frame_targets = targets[static_cast<std::size_t>(k)];
    std::optional<ChainPrior> prior;
    Eigen::VectorXd start = previous;
    const auto started = std::chrono::steady_clock::now();
    if (filter) {
      prior = filter->predict(k == 0 ? 0.0 : motion.times(k) - motion.times(k - 1), q_start);
      start = prior->mean;
    }
    const ChainFitResult fit = fitter.fit(frame_targets, start, prior ? &*prior : nullptr);
    motion.fit_seconds(k) =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (filter) filter->update(fit);
    if (!fit.converged) ++unconverged;
    if (fit.markers_used == 0) {
      motion.notes.push_back(
          "frame " + std::to_string(frames[static_cast<std::size_t>(k)] + 1) +
          " (t = " + std::to_string(motion.times(k)) + " s): no tracked marker present; " +
          (filter ? "the filter's prediction is used" : "the previous frame's pose is kept"));
    }
    motion.coordinates.row(k) = fit.q.transpose();
    motion.iterations(k) = fit.iterations;
    previous = fit.q;
  }
  if (unconverged > 0) {
    motion.notes.push_back(std::to_string(unconverged) +
                           " frame(s) stopped at the iteration limit before converging");
  }
  if (filter && options.filter.mode == FilterMode::kSmoother) {
    motion.coordinates = filter->smoothed();
  }

  motion.marker_errors.resize(count, static_cast<Eigen::Index>(setup.markers.size()));
  motion.rms_mm.resize(count);
  motion.max_mm.resize(count);
  motion.markers_used.resize(count);
  for (Eigen::Index k = 0; k < count; ++k) {
    const ChainFitResult at = fitter.evaluate(targets[static_cast<std::size_t>(k)],
                                              motion.coordinates.row(k).transpose());
    motion.marker_errors.row(k) = at.marker_errors.transpose();
    motion.rms_mm(k) = at.rms_mm;
    motion.max_mm(k) = at.max_mm;
    motion.markers_used(k) = at.markers_used;
  }
  motion.poses = poses_of(skeleton, motion.coordinates);

  // Free bodies against the chain.
  for (std::size_t b = 0; b < skeleton.bodies.size(); ++b) {
    BodyRegistrationSummary summary;
    summary.body = skeleton.bodies[b].name;
    std::vector<double> residuals;
    std::vector<double> gaps;
    const SkeletonBody& body = skeleton.bodies[b];
    for (Eigen::Index k = 0; k < count; ++k) {
      const std::vector<FreeBody>& free = free_bodies[static_cast<std::size_t>(k)];
      if (!free[b].registered) continue;
      residuals.push_back(free[b].rms_mm);
      if (body.parent >= 0 && free[static_cast<std::size_t>(body.parent)].registered) {
        const Eigen::Vector3d from_child = free[b].pose * body.child_offset.translation();
        const Eigen::Vector3d from_parent =
            free[static_cast<std::size_t>(body.parent)].pose *
            (body.parent_offset * joint_motion(body, motion.coordinates.row(k).transpose()))
                .translation();
        gaps.push_back((from_child - from_parent).norm());
      }
    }
    if (residuals.empty()) continue;
    summary.frames_registered = static_cast<int>(residuals.size());
    summary.cluster_rms_mm = median(residuals);
    summary.joint_gap_mm = median(gaps);
    motion.registrations.push_back(summary);
  }
  return motion;
}

}  // namespace mmm::motion

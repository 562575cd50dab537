#include "core/wrapping/global_path.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "core/errors.h"
#include "core/wrapping/path_pieces.h"

namespace mmm::wrapping {
namespace {

using detail::polyline_length;
using Eigen::Vector3d;

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Below this (mm) a distance is zero: the gradient comes from the face normal.
constexpr double kOnSurface = 1e-12;
// Closest points this far inside their face (barycentric) take the face's side.
constexpr double kFaceInterior = 1e-6;
// A query looks this much (mm) beyond the distance it must know exactly, so
// that the memory it leaves covers the next, nearby queries.
constexpr double kReachMargin = 1.0;
// Pushing a start point out of a surface: steps per point, the least cosine
// between the push direction and the distance gradient assumed when sizing
// a step (sideways pushes along a flank need longer steps), and how far
// (mm) beyond the clearance a step aims.
constexpr int kMaxPushSteps = 64;
constexpr double kLeastPushCosine = 0.25;
constexpr double kPushBeyond = 1e-3;
// Active set: start points this close (mm) beyond their clearance start in
// contact; a free point closer than its clearance by more than
// kAddTolerance (mm) comes into contact; a contact is released when the
// path's chord passes outside it by more than kReleasePull (mm).
constexpr double kContactBand = 0.5;
constexpr double kAddTolerance = 1e-3;
constexpr double kReleasePull = 1e-6;
// Solves per segment (each with the active set fixed), and the iterations
// of one while the active set may still change.
constexpr int kMaxRounds = 10;
// After this many rounds contacts are only added, so that an active set
// that keeps changing (a path caught between surfaces) settles, on a
// feasible path that may hold a point or two it could release.
constexpr int kReleaseRounds = 6;
constexpr int kRoundIterations = 3;

std::string describe(const Vector3d& x) {
  std::ostringstream text;
  text << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return text.str();
}

// What a point knows of one surface from its last query at `at` (surface
// frame): the ball of radius |sd| around it lies on the side of sd's sign,
// and `surface_point` (when known) is a point of the surface, whose distance
// bounds the next query's answer from above.
struct Memory {
  Vector3d at = Vector3d::Zero();
  double sd = 0.0;
  std::optional<Vector3d> surface_point;
};

// A signed distance (mm): exact, with its gradient and closest point
// (world), when below the `need` it was asked for; else only known to be
// >= need.
struct Sample {
  double sd = kInfinity;
  Vector3d gradient = Vector3d::Zero();
  Vector3d closest = Vector3d::Zero();
};

// One posed surface, ready for queries in world coordinates.
class Probe {
 public:
  Probe(const PosedSurface& surface, int index)
      : sdf_(surface.sdf),
        pose_(surface.pose),
        to_local_(surface.pose.inverse()),
        box_(surface.sdf->tree().bounds()),
        index_(index) {}

  [[nodiscard]] int index() const { return index_; }

  // sd at world point x, exact when < need. A query, when one is needed,
  // looks as far as `reach` (>= need).
  Sample sample(const Vector3d& x, double need, double reach, Memory& memory) const {
    const Vector3d local = to_local_ * x;
    // Outside the box is outside the surface, at least that far from it.
    const double outside_box = box_.exteriorDistance(local);
    if (outside_box > 0 && outside_box >= need) {
      memory.at = local;
      memory.sd = outside_box;
      return {outside_box, Vector3d::Zero(), Vector3d::Zero()};
    }
    const double moved = (local - memory.at).norm();
    const bool side_known = moved < std::abs(memory.sd);
    if (side_known && memory.sd - moved >= need) {
      return {memory.sd - moved, Vector3d::Zero(), Vector3d::Zero()};
    }
    // The distance is at most that to a known surface point; a tight bound
    // prunes the tree.
    const double known = memory.surface_point ? (local - *memory.surface_point).norm() : kInfinity;
    const double limit = side_known && memory.sd > 0 ? std::min(reach, known) : known;
    std::optional<mesh::AabbTree::ClosestPoint> near;
    if (std::isfinite(limit)) {
      const double padded = limit * (1.0 + 1e-9) + 1e-9;
      near = sdf_->tree().closest_point_within(local, padded * padded);
    }
    if (!near) {
      if (limit < known) {  // outside and farther than reach
        memory.at = local;
        memory.sd = reach;
        return {reach, Vector3d::Zero(), Vector3d::Zero()};
      }
      near = sdf_->tree().closest_point(local);
    }
    const bool inside = side_known ? memory.sd < 0 : is_inside(local, *near);
    return finish(local, *near, inside, memory);
  }

  // The exact signed distance at x, its gradient and closest point.
  Sample exact(const Vector3d& x, Memory& memory) const {
    return sample(x, kInfinity, kInfinity, memory);
  }

 private:
  [[nodiscard]] Vector3d face_normal(int face) const {
    const mesh::IndexedMesh& mesh = sdf_->tree().mesh();
    const Vector3d a = mesh.V.row(mesh.F(face, 0)).transpose();
    const Vector3d b = mesh.V.row(mesh.F(face, 1)).transpose();
    const Vector3d c = mesh.V.row(mesh.F(face, 2)).transpose();
    return (b - a).cross(c - a);
  }

  // The closest face's side when the closest point lies inside it (exact
  // for a closed, consistently oriented mesh), else the winding number.
  [[nodiscard]] bool is_inside(const Vector3d& local,
                               const mesh::AabbTree::ClosestPoint& near) const {
    if (near.barycentric.minCoeff() > kFaceInterior) {
      const Vector3d normal = face_normal(near.face);
      const double side = (local - near.point).dot(normal);
      if (normal.squaredNorm() > 0 && side != 0) return side < 0;
    }
    return sdf_->winding().is_inside(local);
  }

  Sample finish(const Vector3d& local, const mesh::AabbTree::ClosestPoint& near, bool inside,
                Memory& memory) const {
    const double distance = std::sqrt(near.squared_distance);
    Vector3d gradient;
    if (distance > kOnSurface) {
      gradient = (inside ? -1.0 : 1.0) * (local - near.point) / distance;
    } else {
      gradient = face_normal(near.face).normalized();
    }
    const double sd = inside ? -distance : distance;
    memory = {local, sd, near.point};
    return {sd, pose_.linear() * gradient, pose_ * near.point};
  }

  const mesh::SignedDistance* sdf_;
  Eigen::Isometry3d pose_;
  Eigen::Isometry3d to_local_;
  Eigen::AlignedBox3d box_;
  int index_;
};

// The interior points' memories of each probe: at(i, k) for point i and
// probe k.
class Memories {
 public:
  void reset(std::size_t points, std::size_t probes) {
    points_ = points;
    probes_ = probes;
    memories_.assign(points * probes, Memory{});
  }
  // One more probe per point, the new one fresh.
  void add_probe() {
    std::vector<Memory> grown(points_ * (probes_ + 1));
    for (std::size_t i = 0; i < points_; ++i) {
      std::copy_n(memories_.begin() + static_cast<std::ptrdiff_t>(i * probes_), probes_,
                  grown.begin() + static_cast<std::ptrdiff_t>(i * (probes_ + 1)));
    }
    memories_ = std::move(grown);
    ++probes_;
  }
  Memory& at(std::size_t point, std::size_t probe) { return memories_[point * probes_ + probe]; }

 private:
  std::size_t points_ = 0;
  std::size_t probes_ = 0;
  std::vector<Memory> memories_;
};

// The smallest signed distance of point i at x over the probes but `skip`
// (exact when < need), and the probe that gave it (-1 when none did).
struct Nearest {
  Sample sample;
  int probe = -1;
};

Nearest nearest(const Vector3d& x, const std::vector<Probe>& probes, double need,
                Memories& memories, std::size_t point, int skip = -1) {
  Nearest best;
  for (std::size_t k = 0; k < probes.size(); ++k) {
    if (static_cast<int>(k) == skip) continue;
    const Sample sample = probes[k].sample(x, need, need + kReachMargin, memories.at(point, k));
    if (sample.sd < best.sample.sd) best = {sample, static_cast<int>(k)};
  }
  return best;
}

// Residual x_b - x_a between two path points: its square is the chord's
// squared length.
class ChordCost final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Vector3d> a(parameters[0]);
    const Eigen::Map<const Vector3d> b(parameters[1]);
    Eigen::Map<Vector3d> residual(residuals);
    residual = b - a;
    if (jacobians != nullptr) {
      using Jacobian = Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>;
      if (jacobians[0] != nullptr) {
        Jacobian d_a(jacobians[0]);
        d_a = -Eigen::Matrix3d::Identity();
      }
      if (jacobians[1] != nullptr) {
        Jacobian d_b(jacobians[1]);
        d_b = Eigen::Matrix3d::Identity();
      }
    }
    return true;
  }
};

// Residual x - end between a path point and a fixed end of the segment.
class EndChordCost final : public ceres::SizedCostFunction<3, 3> {
 public:
  explicit EndChordCost(Vector3d end) : end_(std::move(end)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Map<Vector3d> residual(residuals);
    residual = Eigen::Map<const Vector3d>(parameters[0]) - end_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> d_x(jacobians[0]);
      d_x = Eigen::Matrix3d::Identity();
    }
    return true;
  }

 private:
  Vector3d end_;
};

// The offset surface {sd = c} of one probe as a Ceres manifold: a point in
// contact slides on it. Tangent basis B from the distance gradient at x;
// Plus(x, delta) is the point of the offset surface nearest x + B delta
// (closest surface point + c * gradient).
class OffsetSurface final : public ceres::Manifold {
 public:
  // `memory`: what the point knew of the surface before.
  OffsetSurface(const Probe& probe, double clearance, Memory memory)
      : probe_(&probe), clearance_(clearance), memory_(std::move(memory)) {}

  [[nodiscard]] int AmbientSize() const override { return 3; }
  [[nodiscard]] int TangentSize() const override { return 2; }

  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    const Eigen::Map<const Vector3d> at(x);
    const Sample sample =
        probe_->exact(at + basis(at) * Eigen::Map<const Eigen::Vector2d>(delta), memory_);
    Eigen::Map<Vector3d> moved(x_plus_delta);
    moved = sample.closest + clearance_ * sample.gradient;
    return moved.allFinite();
  }

  bool PlusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 3, 2, Eigen::RowMajor>> d_delta(jacobian);
    d_delta = basis(Eigen::Map<const Vector3d>(x));
    return true;
  }

  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    const Eigen::Map<const Vector3d> at(x);
    Eigen::Map<Eigen::Vector2d> difference(y_minus_x);
    difference = basis(at).transpose() * (Eigen::Map<const Vector3d>(y) - at);
    return true;
  }

  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> d_y(jacobian);
    d_y = basis(Eigen::Map<const Vector3d>(x)).transpose();
    return true;
  }

 private:
  using Basis = Eigen::Matrix<double, 3, 2>;

  // Ceres asks for the basis at one x several times per iteration: the last
  // one is kept. The manifold writes its caches: Ceres must run on one thread.
  [[nodiscard]] Basis basis(const Vector3d& x) const {
    if (!cached_ || x != cached_at_) {
      const Vector3d normal = probe_->exact(x, memory_).gradient;
      const Vector3d first = normal.unitOrthogonal();
      cached_basis_.col(0) = first;
      cached_basis_.col(1) = normal.cross(first);
      cached_at_ = x;
      cached_ = true;
    }
    return cached_basis_;
  }

  const Probe* probe_;
  double clearance_;
  mutable Memory memory_;
  mutable bool cached_ = false;
  mutable Vector3d cached_at_ = Vector3d::Zero();
  mutable Basis cached_basis_ = Basis::Zero();
};

// `count` points evenly spaced by arc length strictly inside the polyline.
std::vector<Vector3d> resample_interior(std::span<const Vector3d> polyline, int count) {
  std::vector<Vector3d> result;
  result.reserve(static_cast<std::size_t>(count));
  const double total = polyline_length(polyline);
  std::size_t piece = 1;
  double before = 0.0;  // arc length at polyline[piece - 1]
  for (int i = 1; i <= count; ++i) {
    const double target = total * i / (count + 1);
    while (piece + 1 < polyline.size() &&
           before + (polyline[piece] - polyline[piece - 1]).norm() < target) {
      before += (polyline[piece] - polyline[piece - 1]).norm();
      ++piece;
    }
    const double span = (polyline[piece] - polyline[piece - 1]).norm();
    const double t = span > 0 ? std::clamp((target - before) / span, 0.0, 1.0) : 0.0;
    result.emplace_back(polyline[piece - 1] + t * (polyline[piece] - polyline[piece - 1]));
  }
  return result;
}

int interior_count(double length, const GlobalPathOptions& options) {
  const double wanted = std::ceil(length / options.max_spacing_mm) - 1.0;
  return static_cast<int>(std::clamp(wanted, static_cast<double>(options.min_interior_points),
                                     static_cast<double>(options.max_interior_points)));
}

std::vector<Vector3d> with_ends(const Vector3d& a, const std::vector<Vector3d>& interior,
                                const Vector3d& b) {
  std::vector<Vector3d> points;
  points.reserve(interior.size() + 2);
  points.push_back(a);
  points.insert(points.end(), interior.begin(), interior.end());
  points.push_back(b);
  return points;
}

// The previous polyline with its ends moved onto a and b (each point by the
// ends' displacements blended by its arc-length fraction), resampled.
std::vector<Vector3d> carried_over(std::span<const Vector3d> previous, const Vector3d& a,
                                   const Vector3d& b, const GlobalPathOptions& options) {
  const double total = polyline_length(previous);
  const Vector3d shift_a = a - previous.front();
  const Vector3d shift_b = b - previous.back();
  std::vector<Vector3d> moved(previous.begin(), previous.end());
  double along = 0.0;
  for (std::size_t i = 0; i < moved.size(); ++i) {
    if (i > 0) along += (previous[i] - previous[i - 1]).norm();
    const double t = total > 0 ? along / total : 0.0;
    moved[i] += (1.0 - t) * shift_a + t * shift_b;
  }
  moved.front() = a;
  moved.back() = b;
  return resample_interior(moved, interior_count(polyline_length(moved), options));
}

// The least signed distance over the interior points of a straight line
// (exact when < need, else >= need). One memory per surface runs along the
// line, from its start, so that points well clear of a surface need no
// query. Stops early once a point is closer than `enough`.
double check_line(std::span<const Vector3d> line, const std::vector<Probe>& probes, double need,
                  double enough) {
  double least = kInfinity;
  for (const Probe& probe : probes) {
    Memory memory;
    (void)probe.sample(line[0], need, kInfinity, memory);
    for (std::size_t i = 1; i + 1 < line.size() && least >= enough; ++i) {
      least = std::min(least, probe.sample(line[i], need, kInfinity, memory).sd);
    }
  }
  return least;
}

// Moves x along `direction` until it is clear of every surface (or the
// steps run out); returns how far it went.
double march(Vector3d& x, const Vector3d& direction, const std::vector<Probe>& probes,
             double clearance, Memories& memories, std::size_t point) {
  const Vector3d start = x;
  Sample sample = nearest(x, probes, clearance, memories, point).sample;
  for (int step = 0; step < kMaxPushSteps && sample.sd < clearance; ++step) {
    const double cosine = std::max(direction.dot(sample.gradient), kLeastPushCosine);
    x += ((clearance - sample.sd) / cosine + kPushBeyond) * direction;
    sample = nearest(x, probes, clearance, memories, point).sample;
  }
  return (x - start).norm();
}

// Moves every point closer than c to a surface out of it, sideways to the
// path: each run of consecutive such points goes one way, the one of four
// (the mean of their gradients less the path direction d, its opposite,
// and d x that, both ways) that moves them least in all.
void push_out(const Vector3d& a, std::vector<Vector3d>& x, const Vector3d& b,
              const std::vector<Probe>& probes, Memories& memories, double clearance) {
  const std::size_t n = x.size();
  std::vector<Sample> samples(n);
  for (std::size_t i = 0; i < n; ++i) {
    samples[i] = nearest(x[i], probes, clearance, memories, i).sample;
  }
  std::size_t i = 0;
  while (i < n) {
    if (samples[i].sd >= clearance) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < n && samples[end].sd < clearance) ++end;
    const Vector3d chord = (end < n ? x[end] : b) - (i > 0 ? x[i - 1] : a);
    const Vector3d along = chord.norm() > 0 ? Vector3d(chord.normalized()) : Vector3d::UnitX();
    Vector3d mean = Vector3d::Zero();
    for (std::size_t k = i; k < end; ++k) mean += samples[k].gradient;
    mean -= mean.dot(along) * along;
    // A path straight through a centre has no preferred side: pick one.
    const Vector3d first = mean.norm() > 1e-3 * static_cast<double>(end - i)
                               ? Vector3d(mean.normalized())
                               : Vector3d(along.unitOrthogonal());
    const Vector3d second = along.cross(first);
    double best = kInfinity;
    std::vector<Vector3d> chosen;
    for (const Vector3d& direction : {first, Vector3d(-first), second, Vector3d(-second)}) {
      std::vector<Vector3d> moved(x.begin() + static_cast<std::ptrdiff_t>(i),
                                  x.begin() + static_cast<std::ptrdiff_t>(end));
      double total = 0.0;
      for (std::size_t k = i; k < end && total < best; ++k) {
        total += march(moved[k - i], direction, probes, clearance, memories, k);
      }
      if (total < best) {
        best = total;
        chosen = std::move(moved);
      }
    }
    std::copy(chosen.begin(), chosen.end(), x.begin() + static_cast<std::ptrdiff_t>(i));
    i = end;
  }
}

// Which surface each interior point rests on (an index into the probes),
// or -1 for a free point.
using Contacts = std::vector<int>;

Vector3d onto_offset(const Sample& sample, double clearance) {
  return sample.closest + clearance * sample.gradient;
}

// Starts the active set: points within kContactBand beyond their clearance
// rest on the nearest surface, moved onto its offset surface.
Contacts initial_contacts(std::vector<Vector3d>& x, const std::vector<Probe>& probes,
                          Memories& memories, double clearance) {
  Contacts contacts(x.size(), -1);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Nearest near = nearest(x[i], probes, clearance + kContactBand, memories, i);
    if (near.probe >= 0 && near.sample.sd < clearance + kContactBand) {
      contacts[i] = near.probe;
      x[i] = onto_offset(near.sample, clearance);
    }
  }
  return contacts;
}

// Whether the chord from `from` to `to` passes outside x (along `normal`):
// x is then not needed to hold the path off its surface.
bool chord_clears(const Vector3d& from, const Vector3d& to, const Vector3d& x,
                  const Vector3d& normal) {
  const Vector3d chord = to - from;
  const double t = chord.squaredNorm() > 0
                       ? std::clamp((x - from).dot(chord) / chord.squaredNorm(), 0.0, 1.0)
                       : 0.0;
  return (from + t * chord - x).dot(normal) > kReleasePull;
}

// Updates the active set after a solve. Points in contact that the path
// would rather leave are freed, peeling the contacts from both ends of the
// segment: a point goes when the chord from the last contact kept (or the
// segment's end: free points lie on straight lines between them) to its
// next neighbour passes outside it; with immediate neighbours, when the
// pull x_{i-1} + x_{i+1} - 2 x_i points off the surface. Points closer to
// another surface than the clearance by more than kAddTolerance come into
// contact with it. True when the set changed. `release`: false to only add.
bool update_contacts(const Vector3d& a, std::vector<Vector3d>& x, const Vector3d& b,
                     const std::vector<Probe>& probes, Memories& memories, Contacts& contacts,
                     double clearance, bool release) {
  const std::size_t n = x.size();
  std::vector<Vector3d> normals(n, Vector3d::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    if (contacts[i] >= 0) {
      const auto k = static_cast<std::size_t>(contacts[i]);
      normals[i] = probes[k].exact(x[i], memories.at(i, k)).gradient;
    }
  }
  const Contacts before = contacts;
  Vector3d anchor = a;
  for (std::size_t i = 0; i < n && release; ++i) {
    if (before[i] < 0) continue;
    if (chord_clears(anchor, i + 1 < n ? x[i + 1] : b, x[i], normals[i])) {
      contacts[i] = -1;
    } else {
      anchor = x[i];
    }
  }
  anchor = b;
  for (std::size_t i = n; release && i-- > 0;) {
    if (before[i] < 0) continue;
    if (chord_clears(anchor, i > 0 ? x[i - 1] : a, x[i], normals[i])) {
      contacts[i] = -1;
    } else {
      anchor = x[i];
    }
  }
  bool changed = contacts != before;
  for (std::size_t i = 0; i < n; ++i) {
    const Nearest near = nearest(x[i], probes, clearance, memories, i, before[i]);
    if (near.probe >= 0 && near.sample.sd < clearance - kAddTolerance) {
      contacts[i] = near.probe;
      x[i] = onto_offset(near.sample, clearance);
      changed = true;
    }
  }
  return changed;
}

struct SolveReport {
  int iterations = 0;
  bool converged = true;
};

// One Ceres solve with the active set fixed: points in contact slide on
// their offset surfaces, the others are free.
SolveReport solve(const Vector3d& a, std::vector<Vector3d>& x, const Vector3d& b,
                  const std::vector<Probe>& probes, Memories& memories, const Contacts& contacts,
                  const GlobalPathOptions& options, int max_iterations) {
  ceres::Problem problem;
  const std::size_t n = x.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (contacts[i] >= 0) {
      const auto k = static_cast<std::size_t>(contacts[i]);
      problem.AddParameterBlock(
          x[i].data(), 3, new OffsetSurface(probes[k], options.clearance_mm, memories.at(i, k)));
    } else {
      problem.AddParameterBlock(x[i].data(), 3);
    }
  }
  problem.AddResidualBlock(new EndChordCost(a), nullptr, x.front().data());
  for (std::size_t i = 1; i < n; ++i) {
    problem.AddResidualBlock(new ChordCost, nullptr, x[i - 1].data(), x[i].data());
  }
  problem.AddResidualBlock(new EndChordCost(b), nullptr, x.back().data());
  ceres::Solver::Options solver;
  solver.minimizer_type = ceres::TRUST_REGION;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  solver.gradient_tolerance = options.gradient_tolerance;
  solver.logging_type = ceres::SILENT;
  solver.num_threads = 1;  // the manifolds write their caches
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (summary.termination_type == ceres::FAILURE) {
    throw SolverError("global path: Ceres failed: " + summary.BriefReport());
  }
  return {summary.num_successful_steps + summary.num_unsuccessful_steps,
          summary.termination_type == ceres::CONVERGENCE};
}

std::vector<Probe> probes_for(const std::vector<int>& indices,
                              const std::vector<PosedSurface>& surfaces) {
  std::vector<Probe> probes;
  probes.reserve(indices.size());
  for (const int index : indices) {
    probes.emplace_back(surfaces[static_cast<std::size_t>(index)], index);
  }
  return probes;
}

// Surfaces near the path that were not queried and that it runs into: added
// to the probes. True when there was one.
bool take_new_surfaces(const Vector3d& a, const std::vector<Vector3d>& x, const Vector3d& b,
                       const std::vector<PosedSurface>& surfaces, const GlobalPathOptions& options,
                       std::vector<int>& indices, std::vector<Probe>& probes, Memories& memories) {
  const double c = options.clearance_mm;
  bool added = false;
  for (const int index :
       surfaces_near(with_ends(a, x, b), surfaces, options.search_margin_mm + c)) {
    if (std::find(indices.begin(), indices.end(), index) != indices.end()) continue;
    const Probe probe(surfaces[static_cast<std::size_t>(index)], index);
    const bool hit = std::any_of(x.begin(), x.end(), [&](const Vector3d& point) {
      Memory memory;
      return probe.sample(point, c, c, memory).sd < c - kAddTolerance;
    });
    if (!hit) continue;
    indices.push_back(index);
    probes.push_back(probe);
    memories.add_probe();
    added = true;
  }
  return added;
}

void check_options(const GlobalPathOptions& options) {
  const auto fail = [](const std::string& problem) {
    throw InvalidInputError("global path options: " + problem);
  };
  if (!(options.clearance_mm >= 0) || !std::isfinite(options.clearance_mm)) {
    fail("clearance_mm must be a finite number >= 0");
  }
  if (!(options.max_spacing_mm > 0) || !std::isfinite(options.max_spacing_mm)) {
    fail("max_spacing_mm must be a finite number > 0");
  }
  if (options.min_interior_points < 1 ||
      options.max_interior_points < options.min_interior_points) {
    fail("need 1 <= min_interior_points <= max_interior_points, got " +
         std::to_string(options.min_interior_points) + " and " +
         std::to_string(options.max_interior_points));
  }
  if (!(options.search_margin_mm >= 0) || !(options.contact_tolerance_mm >= 0)) {
    fail("search_margin_mm and contact_tolerance_mm must be >= 0");
  }
  if (options.max_iterations < 1) fail("max_iterations must be >= 1");
}

void check_surfaces(const std::vector<PosedSurface>& surfaces) {
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    if (surfaces[s].sdf == nullptr) {
      throw InvalidInputError("global path: surface " + std::to_string(s) +
                              " has no signed distance (sdf is null)");
    }
    if (!surfaces[s].pose.matrix().allFinite()) {
      throw InvalidInputError("global path: surface " + std::to_string(s) +
                              "'s pose is not finite");
    }
  }
}

void check_point(const Vector3d& x, const std::string& what) {
  if (!x.allFinite()) {
    throw InvalidInputError("global path: " + what + " is not finite: " + describe(x) +
                            " (check the pose and the path's points)");
  }
}

// Solves with the active set fixed, updates it, and again, until it holds
// at a converged solve (or the rounds or the iteration budget run out).
// Short solves while the set changes, then the rest of the budget.
void settle(const Vector3d& a, std::vector<Vector3d>& x, const Vector3d& b,
            const std::vector<PosedSurface>& surfaces, const GlobalPathOptions& options,
            std::vector<Probe>& probes, Memories& memories, Contacts& contacts, int& budget,
            GlobalSegment& result) {
  bool stable = false;
  for (int round = 0; round < kMaxRounds && budget > 0; ++round) {
    const SolveReport report = solve(a, x, b, probes, memories, contacts, options,
                                     stable ? budget : std::min(budget, kRoundIterations));
    budget -= report.iterations;
    result.iterations += report.iterations;
    const bool changed =
        update_contacts(a, x, b, probes, memories, contacts, options.clearance_mm,
                        round < kReleaseRounds) ||
        take_new_surfaces(a, x, b, surfaces, options, result.surfaces, probes, memories);
    result.converged = report.converged && !changed;
    if (result.converged) return;
    stable = !changed;
  }
}

// The nearest surface's sample at x (exact when < need).
Sample closest_surface(const Vector3d& x, const std::vector<Probe>& probes, double need) {
  Sample best;
  for (const Probe& probe : probes) {
    Memory memory;
    const Sample sample = probe.sample(x, need, need, memory);
    if (sample.sd < best.sd) best = sample;
  }
  return best;
}

GlobalSegment segment_checked(const Vector3d& a, const Vector3d& b,
                              const std::vector<PosedSurface>& surfaces,
                              const GlobalPathOptions& options,
                              std::span<const Vector3d> warm_start) {
  GlobalSegment result;
  const double c = options.clearance_mm;
  const double contact = c + options.contact_tolerance_mm;
  std::vector<Vector3d> box_points = {a, b};
  box_points.insert(box_points.end(), warm_start.begin(), warm_start.end());
  result.surfaces = surfaces_near(box_points, surfaces, options.search_margin_mm + c);
  std::vector<Probe> probes = probes_for(result.surfaces, surfaces);
  // Ends closer than the clearance to a surface (attachments on a bone, or
  // in it) are lifted onto its offset surface: the path leaves them along
  // the distance gradient, the shortest way out.
  const Sample at_a = closest_surface(a, probes, c);
  const Sample at_b = closest_surface(b, probes, c);
  result.start_inside = at_a.sd < 0;
  result.end_inside = at_b.sd < 0;
  const Vector3d from = at_a.sd < c ? onto_offset(at_a, c) : a;
  const Vector3d to = at_b.sd < c ? onto_offset(at_b, c) : b;
  std::vector<Vector3d> x = resample_interior(std::vector<Vector3d>{from, to},
                                              interior_count((to - from).norm(), options));
  // The straight line, when it keeps its clearance, is the shortest path.
  double least = check_line(with_ends(from, x, to), probes, contact, c);
  if (from != to && least < c) {
    Memories memories;
    if (!warm_start.empty()) x = carried_over(warm_start, from, to, options);
    memories.reset(x.size(), probes.size());
    push_out(from, x, to, probes, memories, c);
    // Pushed out, the path may be much longer than the line: more points.
    const std::vector<Vector3d> pushed = with_ends(from, x, to);
    const int wanted = interior_count(polyline_length(pushed), options);
    if (wanted > static_cast<int>(x.size())) {
      x = resample_interior(pushed, wanted);
      memories.reset(x.size(), probes.size());
      push_out(from, x, to, probes, memories, c);
    }
    Contacts contacts = initial_contacts(x, probes, memories, c);
    int budget = options.max_iterations;
    settle(from, x, to, surfaces, options, probes, memories, contacts, budget, result);
    // The points were spread over the start's length: respread them over
    // the path's and settle again.
    const std::vector<Vector3d> settled = with_ends(from, x, to);
    const int fitting = interior_count(polyline_length(settled), options);
    if (fitting != static_cast<int>(x.size()) && budget > 0) {
      x = resample_interior(settled, fitting);
      memories.reset(x.size(), probes.size());
      contacts = initial_contacts(x, probes, memories, c);
      settle(from, x, to, surfaces, options, probes, memories, contacts, budget, result);
    }
    // Points in contact sit on their offset surface (sd = c); the others
    // are measured.
    least = kInfinity;
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (contacts[i] >= 0) least = std::min(least, c);
      least = std::min(least, nearest(x[i], probes, contact, memories, i, contacts[i]).sample.sd);
    }
  }
  result.touches = least <= contact || from != a || to != b;
  result.max_penetration = -std::min(least, c);
  result.points.push_back(a);
  if (from != a) result.points.push_back(from);
  result.points.insert(result.points.end(), x.begin(), x.end());
  if (to != b) result.points.push_back(to);
  result.points.push_back(b);
  result.length = polyline_length(result.points);
  std::sort(result.surfaces.begin(), result.surfaces.end());
  return result;
}

}  // namespace

Eigen::AlignedBox3d world_bounds(const PosedSurface& surface) {
  const Eigen::AlignedBox3d local = surface.sdf->tree().bounds();
  Eigen::AlignedBox3d world;
  for (const auto corner :
       {Eigen::AlignedBox3d::BottomLeftFloor, Eigen::AlignedBox3d::BottomRightFloor,
        Eigen::AlignedBox3d::TopLeftFloor, Eigen::AlignedBox3d::TopRightFloor,
        Eigen::AlignedBox3d::BottomLeftCeil, Eigen::AlignedBox3d::BottomRightCeil,
        Eigen::AlignedBox3d::TopLeftCeil, Eigen::AlignedBox3d::TopRightCeil}) {
    world.extend(surface.pose * local.corner(corner));
  }
  return world;
}

std::vector<int> surfaces_near(std::span<const Vector3d> points,
                               const std::vector<PosedSurface>& surfaces, double margin_mm) {
  Eigen::AlignedBox3d box;
  for (const Vector3d& point : points) box.extend(point);
  box.min().array() -= margin_mm;
  box.max().array() += margin_mm;
  std::vector<int> near;
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    if (surfaces[s].sdf != nullptr && box.intersects(world_bounds(surfaces[s]))) {
      near.push_back(static_cast<int>(s));
    }
  }
  return near;
}

GlobalSegment global_segment(const Vector3d& a, const Vector3d& b,
                             const std::vector<PosedSurface>& surfaces,
                             const GlobalPathOptions& options,
                             std::span<const Vector3d> warm_start) {
  check_options(options);
  check_surfaces(surfaces);
  check_point(a, "the segment's start");
  check_point(b, "the segment's end");
  for (std::size_t i = 0; i < warm_start.size(); ++i) {
    check_point(warm_start[i], "warm-start point " + std::to_string(i));
  }
  return segment_checked(a, b, surfaces, options,
                         warm_start.size() >= 2 ? warm_start : std::span<const Vector3d>{});
}

GlobalPath global_path(const std::vector<Vector3d>& fixed_points,
                       const std::vector<PosedSurface>& surfaces, const GlobalPathOptions& options,
                       const GlobalPath* warm_start) {
  check_options(options);
  check_surfaces(surfaces);
  if (fixed_points.size() < 2) {
    throw InvalidInputError("global path: needs at least 2 fixed points (origin, insertion), got " +
                            std::to_string(fixed_points.size()));
  }
  for (std::size_t i = 0; i < fixed_points.size(); ++i) {
    check_point(fixed_points[i], "fixed point " + std::to_string(i));
  }
  const bool warm = warm_start != nullptr && warm_start->segments.size() + 1 == fixed_points.size();
  GlobalPath path;
  path.points.push_back(fixed_points.front());
  for (std::size_t i = 1; i < fixed_points.size(); ++i) {
    std::span<const Vector3d> previous;
    if (warm) {
      previous = warm_start->segments[i - 1].points;
      for (std::size_t k = 0; k < previous.size(); ++k) {
        check_point(previous[k],
                    "warm-start segment " + std::to_string(i - 1) + " point " + std::to_string(k));
      }
      if (previous.size() < 2) previous = {};
    }
    GlobalSegment segment =
        segment_checked(fixed_points[i - 1], fixed_points[i], surfaces, options, previous);
    path.points.insert(path.points.end(), segment.points.begin() + 1, segment.points.end());
    path.length += segment.length;
    path.segments.push_back(std::move(segment));
  }
  return path;
}

}  // namespace mmm::wrapping

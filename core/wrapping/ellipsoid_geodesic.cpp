#include "core/wrapping/ellipsoid_geodesic.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/wrapping/path_pieces.h"

namespace mmm::wrapping {
namespace {

using detail::polyline_length;
using detail::straight;
using Eigen::Vector3d;

// Points on the wrapped part: at least / at most this many.
constexpr int kMinArcPoints = 8;
constexpr int kMaxArcPoints = 2000;
// Step (rad) of the first path's great circle on the unit sphere, before it
// is resampled to the M points.
constexpr double kUnitArcStep = 1e-3;
// Majorize-minimize passes, until F decreases by less than kPassTolerance
// of itself.
constexpr int kMaxPasses = 100;
constexpr double kPassTolerance = 1e-12;
// Weight of the residual holding a long-way wrap to its plane (per unit of
// the unit sphere's space): off-plane drift ~ 1 / weight^2.
constexpr double kPlaneWeight = 1e4;

// The points of the unit sphere where the tangents from an end e (|e| > 1,
// unit sphere space) touch it: the circle u . e = 1, |u| = 1, of centre
// e / |e|^2 and radius sqrt(1 - 1 / |e|^2). D maps it onto the ellipsoid's
// tangent points from D e: a path end held on it keeps its straight part
// tangent (free, the straight parts would cut the corner through the body:
// the tangent configuration is a saddle of the length, not a minimum).
class TangentCircle {
 public:
  explicit TangentCircle(const Vector3d& end)
      : centre_(end / end.squaredNorm()),
        radius_(std::sqrt(std::max(0.0, 1.0 - 1.0 / end.squaredNorm()))),
        first_(end.unitOrthogonal()),
        second_(end.normalized().cross(first_)) {}

  [[nodiscard]] Vector3d at(double angle) const {
    return centre_ + radius_ * (std::cos(angle) * first_ + std::sin(angle) * second_);
  }
  [[nodiscard]] Vector3d d_at(double angle) const {
    return radius_ * (-std::sin(angle) * first_ + std::cos(angle) * second_);
  }
  // The angle of a point on (or near) the circle.
  [[nodiscard]] double angle_of(const Vector3d& u) const {
    return std::atan2((u - centre_).dot(second_), (u - centre_).dot(first_));
  }

 private:
  Vector3d centre_;
  double radius_;
  Vector3d first_;
  Vector3d second_;
};

// A path point's parameter block: an angle on a tangent circle (size 1) or a
// unit vector u (size 3); where it puts the point and d(point)/d(block).
template <int kSize>
using PointJacobian =
    Eigen::Matrix<double, 3, kSize, kSize == 1 ? Eigen::ColMajor : Eigen::RowMajor>;

template <int kSize>
Vector3d place(const TangentCircle* circle, const double* block) {
  if constexpr (kSize == 1) {
    return circle->at(block[0]);
  } else {
    return Eigen::Map<const Vector3d>(block);
  }
}

template <int kSize>
PointJacobian<kSize> d_place(const TangentCircle* circle, const double* block) {
  if constexpr (kSize == 1) {
    return circle->d_at(block[0]);
  } else {
    return Eigen::Matrix3d::Identity();
  }
}

// Residual root_weight * (D u - end) of an end's straight part (u on its
// tangent circle): its square is weight times the part's squared length.
// The weight is shared, updated between passes.
class StraightPart final : public ceres::SizedCostFunction<3, 1> {
 public:
  StraightPart(Vector3d radii, Vector3d end, const TangentCircle& circle, const double* root_weight)
      : radii_(std::move(radii)),
        end_(std::move(end)),
        circle_(&circle),
        root_weight_(root_weight) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Map<Vector3d> residual(residuals);
    residual = *root_weight_ * (radii_.cwiseProduct(circle_->at(parameters[0][0])) - end_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Vector3d> d_angle(jacobians[0]);
      d_angle = *root_weight_ * radii_.cwiseProduct(circle_->d_at(parameters[0][0]));
    }
    return true;
  }

 private:
  Vector3d radii_;
  Vector3d end_;
  const TangentCircle* circle_;
  const double* root_weight_;
};

// Residual root_lambda * D (u_b - u_a) of a chord of the wrapped part: its
// square is lambda times the chord's squared length. A block of size 1 is
// an angle on the circle given for it.
template <int kSizeA, int kSizeB>
class ArcChord final : public ceres::SizedCostFunction<3, kSizeA, kSizeB> {
 public:
  ArcChord(Vector3d radii, const double* root_lambda, const TangentCircle* circle_a,
           const TangentCircle* circle_b)
      : radii_(std::move(radii)),
        root_lambda_(root_lambda),
        circle_a_(circle_a),
        circle_b_(circle_b) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Vector3d a = place<kSizeA>(circle_a_, parameters[0]);
    const Vector3d b = place<kSizeB>(circle_b_, parameters[1]);
    Eigen::Map<Vector3d> residual(residuals);
    residual = *root_lambda_ * radii_.cwiseProduct(b - a);
    if (jacobians != nullptr) {
      const Eigen::Matrix3d scale = *root_lambda_ * radii_.asDiagonal().toDenseMatrix();
      if (jacobians[0] != nullptr) {
        Eigen::Map<PointJacobian<kSizeA>> d_a(jacobians[0]);
        d_a = -scale * d_place<kSizeA>(circle_a_, parameters[0]);
      }
      if (jacobians[1] != nullptr) {
        Eigen::Map<PointJacobian<kSizeB>> d_b(jacobians[1]);
        d_b = scale * d_place<kSizeB>(circle_b_, parameters[1]);
      }
    }
    return true;
  }

 private:
  Vector3d radii_;
  const double* root_lambda_;
  const TangentCircle* circle_a_;
  const TangentCircle* circle_b_;
};

// Residual weight * n . u: u held to the plane through the origin normal
// to n (unit sphere space).
template <int kSize>
class OnPlane final : public ceres::SizedCostFunction<1, kSize> {
 public:
  OnPlane(Vector3d normal, const TangentCircle* circle)
      : normal_(std::move(normal)), circle_(circle) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = kPlaneWeight * normal_.dot(place<kSize>(circle_, parameters[0]));
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 1, kSize, Eigen::RowMajor>> d_block(jacobians[0]);
      d_block = kPlaneWeight * normal_.transpose() * d_place<kSize>(circle_, parameters[0]);
    }
    return true;
  }

 private:
  Vector3d normal_;
  const TangentCircle* circle_;
};

// `count` points evenly spaced by arc length along the polyline, its ends
// included.
std::vector<Vector3d> resample(const std::vector<Vector3d>& polyline, int count) {
  const double total = polyline_length(polyline);
  std::vector<Vector3d> result;
  result.reserve(static_cast<std::size_t>(count));
  std::size_t piece = 1;
  double before = 0.0;  // arc length at polyline[piece - 1]
  for (int i = 0; i < count; ++i) {
    const double target = total * i / (count - 1);
    while (piece + 1 < polyline.size() &&
           before + (polyline[piece] - polyline[piece - 1]).norm() < target) {
      before += (polyline[piece] - polyline[piece - 1]).norm();
      ++piece;
    }
    const double span = (polyline[piece] - polyline[piece - 1]).norm();
    const double t = span > 0 ? std::clamp((target - before) / span, 0.0, 1.0) : 0.0;
    result.emplace_back(polyline[piece - 1] + t * (polyline[piece] - polyline[piece - 1]));
  }
  result.back() = polyline.back();
  return result;
}

// Normal curvature of the ellipsoid sum (x_i / r_i)^2 = 1 at x (on it) along
// the unit tangent t: t^T H t / |grad f| for f = sum (x_i / r_i)^2 - 1.
double normal_curvature(const Vector3d& x, const Vector3d& t, const Vector3d& radii) {
  const Vector3d inverse_squares = radii.cwiseProduct(radii).cwiseInverse();
  return t.cwiseProduct(t).dot(inverse_squares) / x.cwiseProduct(inverse_squares).norm();
}

// The arc of the surface over the chord a-b (both on it).
double arc_over_chord(const Vector3d& a, const Vector3d& b, const Vector3d& radii) {
  const double chord = (b - a).norm();
  if (chord == 0) return 0.0;
  const Vector3d middle = 0.5 * (a + b);
  const Vector3d on_surface = middle / middle.cwiseQuotient(radii).norm();
  const double kappa = normal_curvature(on_surface, (b - a) / chord, radii);
  return chord * (1.0 + kappa * kappa * chord * chord / 24.0);
}

}  // namespace

WrapResult wrap_ellipsoid(const Vector3d& p_world, const Vector3d& s_world,
                          const Obstacle& obstacle, const WrapOptions& options) {
  const Vector3d& radii = obstacle.radii;
  const Eigen::Isometry3d to_local = obstacle.pose.inverse();
  const Vector3d p = to_local * p_world;
  const Vector3d s = to_local * s_world;
  // The unit sphere's space: whether and where the path wraps.
  Obstacle unit;
  unit.shape = ObstacleShape::kSphere;
  unit.radius = 1.0;
  unit.quadrant = obstacle.quadrant;
  WrapOptions fine;
  fine.arc_step_mm = kUnitArcStep;
  fine.shrink_to_inside_points = false;  // the caller has shrunk the ellipsoid if it had to
  const WrapResult sphere =
      wrap_segment(p.cwiseQuotient(radii), s.cwiseQuotient(radii), unit, fine);
  if (sphere.inside) return straight(p_world, s_world, true);
  if (!sphere.wrapped) return straight(p_world, s_world, false);
  // A quadrant that sends the path the long way round: off its plane that
  // path is no local minimum (it would slide back to the short way), so it
  // is held to the plane of its great circle, through P, S and the centre.
  bool held = false;
  if (obstacle.quadrant != "all" && !obstacle.quadrant.empty()) {
    Obstacle free = unit;
    free.quadrant = "all";
    const WrapResult shortest =
        wrap_segment(p.cwiseQuotient(radii), s.cwiseQuotient(radii), free, fine);
    held = (shortest.tangent_in - sphere.tangent_in).norm() > 1e-9;
  }
  // The first path: the great circle's image, resampled to M points.
  std::vector<Vector3d> image;
  image.reserve(sphere.points.size() - 2);
  for (std::size_t k = 1; k + 1 < sphere.points.size(); ++k) {
    image.emplace_back(radii.cwiseProduct(sphere.points[k]));
  }
  const double first_length = polyline_length(image);
  const int count = static_cast<int>(
      std::clamp(std::ceil(first_length / std::max(options.arc_step_mm, 1e-6)) + 1.0,
                 static_cast<double>(kMinArcPoints), static_cast<double>(kMaxArcPoints)));
  const std::vector<Vector3d> first_path = resample(image, count);
  // Ends on their tangent circles, the points between them on the sphere.
  const TangentCircle circle_in(p.cwiseQuotient(radii));
  const TangentCircle circle_out(s.cwiseQuotient(radii));
  double angle_in = circle_in.angle_of(sphere.tangent_in);
  double angle_out = circle_out.angle_of(sphere.tangent_out);
  std::vector<Vector3d> u;
  u.reserve(static_cast<std::size_t>(count - 2));
  for (int i = 1; i + 1 < count; ++i) {
    u.push_back(first_path[static_cast<std::size_t>(i)].cwiseQuotient(radii).normalized());
  }
  const auto points = [&] {
    std::vector<Vector3d> x;
    x.reserve(static_cast<std::size_t>(count));
    x.emplace_back(radii.cwiseProduct(circle_in.at(angle_in)));
    for (const Vector3d& point : u) x.emplace_back(radii.cwiseProduct(point));
    x.emplace_back(radii.cwiseProduct(circle_out.at(angle_out)));
    return x;
  };

  ceres::Problem problem;
  double root_in = 0.0;
  double root_lambda = 0.0;
  double root_out = 0.0;
  for (Vector3d& point : u) {
    problem.AddParameterBlock(point.data(), 3, new ceres::SphereManifold<3>());
  }
  problem.AddResidualBlock(new StraightPart(radii, p, circle_in, &root_in), nullptr, &angle_in);
  problem.AddResidualBlock(new ArcChord<1, 3>(radii, &root_lambda, &circle_in, nullptr), nullptr,
                           &angle_in, u.front().data());
  for (std::size_t i = 1; i < u.size(); ++i) {
    problem.AddResidualBlock(new ArcChord<3, 3>(radii, &root_lambda, nullptr, nullptr), nullptr,
                             u[i - 1].data(), u[i].data());
  }
  problem.AddResidualBlock(new ArcChord<3, 1>(radii, &root_lambda, nullptr, &circle_out), nullptr,
                           u.back().data(), &angle_out);
  problem.AddResidualBlock(new StraightPart(radii, s, circle_out, &root_out), nullptr, &angle_out);
  if (held) {
    const Vector3d middle = sphere.points[sphere.points.size() / 2];
    const Vector3d normal = sphere.tangent_in.cross(middle).normalized();
    problem.AddResidualBlock(new OnPlane<1>(normal, &circle_in), nullptr, &angle_in);
    for (Vector3d& point : u) {
      problem.AddResidualBlock(new OnPlane<3>(normal, nullptr), nullptr, point.data());
    }
    problem.AddResidualBlock(new OnPlane<1>(normal, &circle_out), nullptr, &angle_out);
  }
  ceres::Solver::Options solver;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = 100;
  solver.function_tolerance = 1e-14;
  solver.gradient_tolerance = 1e-14;
  solver.parameter_tolerance = 1e-12;
  solver.logging_type = ceres::SILENT;
  solver.num_threads = 1;
  // F at the current points, and the next pass's weights from them.
  const auto reweigh = [&] {
    const std::vector<Vector3d> x = points();
    const double in = (x.front() - p).norm();
    const double out = (s - x.back()).norm();
    double energy = 0.0;
    for (std::size_t i = 1; i < x.size(); ++i) energy += (x[i] - x[i - 1]).squaredNorm();
    const double spread = std::sqrt(static_cast<double>(count - 1) * energy);
    root_in = std::sqrt(0.5 / in);
    root_lambda = std::sqrt(0.5 * static_cast<double>(count - 1) / spread);
    root_out = std::sqrt(0.5 / out);
    return in + spread + out;
  };
  double objective = reweigh();
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    if (summary.termination_type == ceres::FAILURE) {
      throw SolverError("ellipsoid wrap: Ceres failed: " + summary.BriefReport());
    }
    const double previous = objective;
    objective = reweigh();
    if (previous - objective <= kPassTolerance * objective) break;
  }

  WrapResult result;
  result.wrapped = true;
  const std::vector<Vector3d> x = points();
  result.points.push_back(p_world);
  double arcs = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    result.points.push_back(obstacle.pose * x[i]);
    if (i == 0) continue;
    arcs += arc_over_chord(x[i - 1], x[i], radii);
    const Vector3d normal = x[i].cwiseQuotient(radii.cwiseProduct(radii)).normalized();
    const Vector3d before = x[i - 1].cwiseQuotient(radii.cwiseProduct(radii)).normalized();
    result.wrap_angle += std::atan2(before.cross(normal).norm(), before.dot(normal));
  }
  result.points.push_back(s_world);
  result.tangent_in = result.points[1];
  result.tangent_out = result.points[result.points.size() - 2];
  result.length = (x.front() - p).norm() + arcs + (s - x.back()).norm();
  return result;
}

}  // namespace mmm::wrapping

#include "core/wrapping/obstacle_set.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/wrapping/ellipsoid_geodesic.h"
#include "core/wrapping/path_pieces.h"

namespace mmm::wrapping {
namespace {

using detail::straight;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// The wrap of a 2D segment p -> s around the circle of radius r at the
// origin, going counter-clockwise (ccw) or clockwise.
struct CircleWrap {
  double from = 0.0;   // angle of T1
  double sweep = 0.0;  // signed angle from T1 to T2 (ccw > 0)
  Eigen::Vector2d t1 = Eigen::Vector2d::Zero();
  Eigen::Vector2d t2 = Eigen::Vector2d::Zero();
};

CircleWrap circle_wrap(const Eigen::Vector2d& p, const Eigen::Vector2d& s, double r, bool ccw) {
  const double ap = std::atan2(p.y(), p.x());
  const double as = std::atan2(s.y(), s.x());
  const double bp = std::acos(std::min(1.0, r / p.norm()));
  const double bs = std::acos(std::min(1.0, r / s.norm()));
  CircleWrap wrap;
  const double first = ccw ? ap + bp : ap - bp;
  const double last = ccw ? as - bs : as + bs;
  double sweep = std::fmod(ccw ? last - first : first - last, kTwoPi);
  if (sweep < 0) sweep += kTwoPi;
  wrap.from = first;
  wrap.sweep = ccw ? sweep : -sweep;
  wrap.t1 = r * Eigen::Vector2d(std::cos(first), std::sin(first));
  wrap.t2 = r * Eigen::Vector2d(std::cos(last), std::sin(last));
  return wrap;
}

// Whether the segment p -> s passes closer than r to the origin.
bool segment_hits_circle(const Eigen::Vector2d& p, const Eigen::Vector2d& s, double r) {
  const Eigen::Vector2d d = s - p;
  const double t = d.squaredNorm() > 0 ? std::clamp(-p.dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p + t * d).norm() < r;
}

// The allowed side: +1/-1 along axis 0 (x) or 1 (y) of the obstacle frame,
// or axis -1 for "all".
struct Quadrant {
  int axis = -1;
  double sign = 1.0;
};

Quadrant parse_quadrant(const std::string& quadrant, ObstacleShape shape) {
  if (quadrant == "all" || quadrant.empty()) return {};
  const bool has_z = shape != ObstacleShape::kCylinder;
  if (quadrant.size() == 2 && (quadrant[0] == '+' || quadrant[0] == '-') &&
      (quadrant[1] == 'x' || quadrant[1] == 'y' || (quadrant[1] == 'z' && has_z))) {
    return {quadrant[1] - 'x', quadrant[0] == '+' ? 1.0 : -1.0};
  }
  throw InvalidInputError("wrap obstacle: quadrant '" + quadrant +
                          "' is not one of all, +x, -x, +y, -y" + (has_z ? ", +z, -z" : ""));
}

// Picks the side: the shorter sweep, or the one whose arc midpoint lies on
// the allowed side (`midpoint_side` gives its signed coordinate).
template <class MidpointSide>
const CircleWrap& choose(const CircleWrap& ccw, const CircleWrap& cw, const Quadrant& quadrant,
                         MidpointSide midpoint_side) {
  if (quadrant.axis < 0) return std::abs(ccw.sweep) <= std::abs(cw.sweep) ? ccw : cw;
  return midpoint_side(ccw) >= midpoint_side(cw) ? ccw : cw;
}

int arc_steps(double arc_length, double step) {
  return std::max(1, static_cast<int>(std::ceil(arc_length / std::max(step, 1e-6))));
}

WrapResult wrap_sphere(const Eigen::Vector3d& p_world, const Eigen::Vector3d& s_world,
                       const Obstacle& obstacle, const Quadrant& quadrant,
                       const WrapOptions& options) {
  const Eigen::Vector3d c = obstacle.pose.translation();
  const double r = obstacle.radius;
  const Eigen::Vector3d p = p_world - c;
  const Eigen::Vector3d s = s_world - c;
  if (p.norm() <= r || s.norm() <= r) return straight(p_world, s_world, true);
  // The plane of c, P and S: e1 toward P, e2 in the plane toward S (or,
  // with P, c and S in line, toward the allowed side).
  const Eigen::Vector3d e1 = p.normalized();
  Eigen::Vector3d e2 = s - s.dot(e1) * e1;
  if (e2.norm() < 1e-9 * s.norm()) {
    const Eigen::Vector3d preferred =
        quadrant.axis >= 0
            ? Eigen::Vector3d(quadrant.sign * obstacle.pose.linear().col(quadrant.axis))
            : Eigen::Vector3d(e1.unitOrthogonal());
    e2 = preferred - preferred.dot(e1) * e1;
    if (e2.norm() < 1e-9) e2 = e1.unitOrthogonal();
  }
  e2.normalize();
  const Eigen::Vector2d p2(p.norm(), 0.0);
  const Eigen::Vector2d s2(s.dot(e1), s.dot(e2));
  const auto to_world = [&](const Eigen::Vector2d& x) -> Eigen::Vector3d {
    return c + x.x() * e1 + x.y() * e2;
  };
  const CircleWrap ccw = circle_wrap(p2, s2, r, true);
  const CircleWrap cw = circle_wrap(p2, s2, r, false);
  const auto side = [&](const CircleWrap& wrap) {
    const double middle = wrap.from + 0.5 * wrap.sweep;
    const Eigen::Vector3d point = to_world(r * Eigen::Vector2d(std::cos(middle), std::sin(middle)));
    return quadrant.sign * (obstacle.pose.inverse() * point)(quadrant.axis);
  };
  const bool hits = segment_hits_circle(p2, s2, r);
  if (!hits) return straight(p_world, s_world, false);
  const CircleWrap& wrap = choose(ccw, cw, quadrant, side);
  WrapResult result;
  result.wrapped = true;
  result.wrap_angle = std::abs(wrap.sweep);
  result.tangent_in = to_world(wrap.t1);
  result.tangent_out = to_world(wrap.t2);
  result.length = (wrap.t1 - p2).norm() + r * result.wrap_angle + (s2 - wrap.t2).norm();
  const int steps = arc_steps(r * result.wrap_angle, options.arc_step_mm);
  result.points.push_back(p_world);
  for (int k = 0; k <= steps; ++k) {
    const double angle = wrap.from + wrap.sweep * k / steps;
    result.points.push_back(to_world(r * Eigen::Vector2d(std::cos(angle), std::sin(angle))));
  }
  result.points.push_back(s_world);
  return result;
}

WrapResult wrap_cylinder(const Eigen::Vector3d& p_world, const Eigen::Vector3d& s_world,
                         const Obstacle& obstacle, const Quadrant& quadrant,
                         const WrapOptions& options) {
  const double r = obstacle.radius;
  const Eigen::Isometry3d to_local = obstacle.pose.inverse();
  const Eigen::Vector3d p = to_local * p_world;
  const Eigen::Vector3d s = to_local * s_world;
  const Eigen::Vector2d p2 = p.head<2>();
  const Eigen::Vector2d s2 = s.head<2>();
  if (p2.norm() <= r || s2.norm() <= r) return straight(p_world, s_world, true);
  if (!segment_hits_circle(p2, s2, r)) return straight(p_world, s_world, false);
  const CircleWrap ccw = circle_wrap(p2, s2, r, true);
  const CircleWrap cw = circle_wrap(p2, s2, r, false);
  const auto side = [&](const CircleWrap& wrap) {
    const double middle = wrap.from + 0.5 * wrap.sweep;
    return quadrant.sign * (quadrant.axis == 0 ? std::cos(middle) : std::sin(middle));
  };
  const CircleWrap& wrap = choose(ccw, cw, quadrant, side);
  // Unrolled: the xy-length of each part, z linear in it.
  const double in = (wrap.t1 - p2).norm();
  const double arc = r * std::abs(wrap.sweep);
  const double out = (s2 - wrap.t2).norm();
  const double planar = in + arc + out;
  const double rise = s.z() - p.z();
  const auto z_at = [&](double along) { return p.z() + rise * along / planar; };
  const auto helix = [&](double fraction) -> Eigen::Vector3d {
    const double angle = wrap.from + wrap.sweep * fraction;
    return obstacle.pose *
           Eigen::Vector3d(r * std::cos(angle), r * std::sin(angle), z_at(in + arc * fraction));
  };
  WrapResult result;
  result.wrapped = true;
  result.wrap_angle = std::abs(wrap.sweep);
  result.tangent_in = helix(0.0);
  result.tangent_out = helix(1.0);
  result.length = std::hypot(planar, rise);
  const int steps = arc_steps(std::hypot(arc, rise * arc / planar), options.arc_step_mm);
  result.points.push_back(p_world);
  for (int k = 0; k <= steps; ++k) result.points.push_back(helix(static_cast<double>(k) / steps));
  result.points.push_back(s_world);
  return result;
}

// How far out `point` lies, as a multiple of the obstacle's size (1 on its
// surface): distance from the centre over the radius (a cylinder: from the
// axis), for an ellipsoid |q ./ radii|.
double size_ratio(const Eigen::Vector3d& point, const Obstacle& obstacle) {
  const Eigen::Vector3d q = obstacle.pose.inverse() * point;
  switch (obstacle.shape) {
    case ObstacleShape::kSphere:
      return q.norm() / obstacle.radius;
    case ObstacleShape::kCylinder:
      return q.head<2>().norm() / obstacle.radius;
    case ObstacleShape::kEllipsoid:
      return q.cwiseQuotient(obstacle.radii).norm();
  }
  return 1.0;
}

// Inside points are kept this fraction of their distance outside the shrunk
// obstacle; below kSmallestShrink (a point at the centre) the segment stays
// straight.
constexpr double kShrinkMargin = 0.999;
constexpr double kSmallestShrink = 0.02;
// The shrinking starts smoothly over this fraction of the size around the
// surface: the size follows the point with a continuous derivative, so the
// moment arm (the length's derivative) does not jump where it starts.
constexpr double kShrinkBlend = 0.3;

// min(a, b) with the corner rounded over `k` (quadratic: continuous first
// derivative; equal to min(a, b) once |a - b| >= k, never above it).
double smooth_min(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k / 4.0;
}

}  // namespace

WrapResult wrap_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& s,
                        const Obstacle& obstacle, const WrapOptions& options) {
  if (obstacle.shape == ObstacleShape::kEllipsoid) {
    if (!(obstacle.radii.minCoeff() > 0) || !obstacle.radii.allFinite()) {
      throw InvalidInputError(
          "wrap obstacle: an ellipsoid's radii (its three semi-axes) must be positive numbers of "
          "mm");
    }
  } else if (!(obstacle.radius > 0) || !std::isfinite(obstacle.radius)) {
    throw InvalidInputError("wrap obstacle: the radius must be a positive number of mm");
  }
  if (!p.allFinite() || !s.allFinite()) {
    throw InvalidInputError("wrap obstacle: the path's end points must be finite");
  }
  const Quadrant quadrant = parse_quadrant(obstacle.quadrant, obstacle.shape);
  // Points on the surface or just outside it shrink the obstacle too (by
  // at most the margin), so the shrinking starts continuously.
  if (options.shrink_to_inside_points) {
    const double nearest = std::min(size_ratio(p, obstacle), size_ratio(s, obstacle));
    const double shrink = smooth_min(1.0, kShrinkMargin * nearest, kShrinkBlend);
    if (shrink < kSmallestShrink) return straight(p, s, true);
    if (shrink < 1.0) {
      Obstacle smaller = obstacle;
      smaller.radius *= shrink;
      smaller.radii *= shrink;
      WrapOptions plain = options;
      plain.shrink_to_inside_points = false;
      WrapResult result = wrap_segment(p, s, smaller, plain);
      result.inside = nearest <= 1.0;
      return result;
    }
  }
  switch (obstacle.shape) {
    case ObstacleShape::kSphere:
      return wrap_sphere(p, s, obstacle, quadrant, options);
    case ObstacleShape::kCylinder:
      return wrap_cylinder(p, s, obstacle, quadrant, options);
    case ObstacleShape::kEllipsoid:
      break;
  }
  return wrap_ellipsoid(p, s, obstacle, options);
}

}  // namespace mmm::wrapping

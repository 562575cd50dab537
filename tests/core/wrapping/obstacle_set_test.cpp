// Obstacle-set wrapping against the analytic geodesics of a sphere (a great
// circle between tangent points) and a cylinder (a helix: a straight line
// on the unrolled surface), with their lengths computed independently here.

#include "core/wrapping/obstacle_set.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "tests/support/test_helpers.h"

namespace mmm::wrapping {
namespace {

using Eigen::Vector3d;

using test::polyline_length;

// Great-circle wrap on the near side, from the geometry alone: the angle
// between P and S seen from the centre, less the two tangent angles.
double sphere_geodesic(const Vector3d& p, const Vector3d& s, double r, bool long_way) {
  const double gamma = std::acos(p.normalized().dot(s.normalized()));
  const double around = long_way ? 2.0 * std::numbers::pi - gamma : gamma;
  const double theta = around - std::acos(r / p.norm()) - std::acos(r / s.norm());
  return std::sqrt(p.squaredNorm() - r * r) + std::sqrt(s.squaredNorm() - r * r) + r * theta;
}

Obstacle sphere_obstacle_at(const Vector3d& centre, double radius,
                            const std::string& quadrant = "all") {
  Obstacle obstacle;
  obstacle.shape = ObstacleShape::kSphere;
  obstacle.pose.translation() = centre;
  obstacle.pose.linear() = Eigen::AngleAxisd(0.4, Vector3d(1, 1, 0).normalized()).matrix();
  obstacle.radius = radius;
  obstacle.quadrant = quadrant;
  return obstacle;
}

TEST(ObstacleSetTest, SphereWrapIsTheGreatCircleGeodesic) {
  const Vector3d c(10, 20, 30);
  const Obstacle sphere = sphere_obstacle_at(c, 40.0);
  const Vector3d p = c + Vector3d(-80, -20, 10);
  const Vector3d s = c + Vector3d(90, -25, -5);
  WrapOptions fine;
  fine.arc_step_mm = 0.05;
  const WrapResult wrap = wrap_segment(p, s, sphere, fine);
  ASSERT_TRUE(wrap.wrapped);
  EXPECT_NEAR(wrap.length, sphere_geodesic(p - c, s - c, 40.0, false), 1e-9);
  // The polyline converges to the same length (chords of 0.05 mm on a
  // 40 mm circle fall short by ~1e-7 relative).
  EXPECT_NEAR(polyline_length(wrap.points), wrap.length, 1e-5 * wrap.length);
  // Straight parts are tangent; the wrapped part lies on the sphere; no
  // point is inside it.
  EXPECT_NEAR((wrap.tangent_in - p).normalized().dot((wrap.tangent_in - c).normalized()), 0, 1e-12);
  EXPECT_NEAR((wrap.tangent_out - s).normalized().dot((wrap.tangent_out - c).normalized()), 0,
              1e-12);
  for (std::size_t i = 1; i + 1 < wrap.points.size(); ++i) {
    EXPECT_NEAR((wrap.points[i] - c).norm(), 40.0, 1e-9);
  }
}

TEST(ObstacleSetTest, AQuadrantSendsTheSphereWrapTheLongWayRound) {
  Obstacle sphere = sphere_obstacle_at(Vector3d::Zero(), 40.0);
  sphere.pose.linear().setIdentity();
  const Vector3d p(-80, -20, 0);
  const Vector3d s(90, -25, 0);
  const WrapResult near = wrap_segment(p, s, sphere);
  ASSERT_TRUE(near.wrapped);
  EXPECT_LT(near.points[near.points.size() / 2].y(), 0);  // the short way is below
  sphere.quadrant = "+y";
  const WrapResult forced = wrap_segment(p, s, sphere);
  ASSERT_TRUE(forced.wrapped);
  EXPECT_GT(forced.points[forced.points.size() / 2].y(), 0);
  EXPECT_NEAR(forced.length, sphere_geodesic(p, s, 40.0, true), 1e-9);
  EXPECT_GT(forced.length, near.length);
}

TEST(ObstacleSetTest, ASegmentThatMissesStaysStraightAndInsidePointsAreFlagged) {
  const Obstacle sphere = sphere_obstacle_at(Vector3d::Zero(), 10.0);
  const WrapResult miss = wrap_segment(Vector3d(-50, 30, 0), Vector3d(50, 30, 0), sphere);
  EXPECT_FALSE(miss.wrapped);
  EXPECT_DOUBLE_EQ(miss.length, 100.0);
  ASSERT_EQ(miss.points.size(), 2u);
  const WrapResult inside = wrap_segment(Vector3d(1, 0, 0), Vector3d(50, 0, 0), sphere);
  EXPECT_TRUE(inside.inside);
  EXPECT_FALSE(inside.wrapped);
}

TEST(ObstacleSetTest, CylinderWrapIsAHelixTheUnrolledStraightLine) {
  Obstacle cylinder;
  cylinder.shape = ObstacleShape::kCylinder;
  cylinder.radius = 30.0;
  cylinder.pose.translation() = Vector3d(5, -7, 100);
  // Axis along the world's x: a femoral-condyle-like roller.
  cylinder.pose.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Vector3d::UnitY()).matrix();
  const Vector3d p_local(-60, -25, -40);
  const Vector3d s_local(70, -20, 55);
  const Vector3d p = cylinder.pose * p_local;
  const Vector3d s = cylinder.pose * s_local;
  WrapOptions fine;
  fine.arc_step_mm = 0.05;
  const WrapResult wrap = wrap_segment(p, s, cylinder, fine);
  ASSERT_TRUE(wrap.wrapped);
  // Unrolled: xy tangent lengths + arc, then Pythagoras with the rise.
  const Eigen::Vector2d p2 = p_local.head<2>();
  const Eigen::Vector2d s2 = s_local.head<2>();
  const double gamma = std::acos(p2.normalized().dot(s2.normalized()));
  const double theta = gamma - std::acos(30.0 / p2.norm()) - std::acos(30.0 / s2.norm());
  const double planar =
      std::sqrt(p2.squaredNorm() - 900) + std::sqrt(s2.squaredNorm() - 900) + 30.0 * theta;
  EXPECT_NEAR(wrap.wrap_angle, theta, 1e-12);
  EXPECT_NEAR(wrap.length, std::hypot(planar, s_local.z() - p_local.z()), 1e-9);
  EXPECT_NEAR(polyline_length(wrap.points), wrap.length, 1e-5 * wrap.length);
  // On the surface, with one slope throughout (a helix), and the same slope
  // on the straight parts: a straight line once unrolled.
  const double slope = (s_local.z() - p_local.z()) / planar;
  const Eigen::Isometry3d to_local = cylinder.pose.inverse();
  for (std::size_t i = 1; i < wrap.points.size(); ++i) {
    const Vector3d a = to_local * wrap.points[i - 1];
    const Vector3d b = to_local * wrap.points[i];
    const double run = (b.head<2>() - a.head<2>()).norm();
    EXPECT_NEAR(b.z() - a.z(), slope * run, 1e-6 * (1.0 + run));
    if (i + 1 < wrap.points.size()) {
      EXPECT_NEAR(b.head<2>().norm(), 30.0, 1e-9);
    }
  }
}

TEST(ObstacleSetTest, BadObstaclesAreErrors) {
  Obstacle obstacle = sphere_obstacle_at(Vector3d::Zero(), 0.0);
  EXPECT_THROW(wrap_segment(Vector3d(-50, 0, 0), Vector3d(50, 0, 0), obstacle), InvalidInputError);
  obstacle.radius = 10;
  obstacle.quadrant = "+q";
  EXPECT_THROW(wrap_segment(Vector3d(-50, 0, 0), Vector3d(50, 0, 0), obstacle), InvalidInputError);
  obstacle.quadrant = "all";
  EXPECT_THROW(wrap_segment(Vector3d(std::nan(""), 0, 0), Vector3d(50, 0, 0), obstacle),
               InvalidInputError);
  obstacle.shape = ObstacleShape::kCylinder;
  obstacle.quadrant = "+z";  // along a cylinder's axis there is no side
  EXPECT_THROW(wrap_segment(Vector3d(-50, 0, 0), Vector3d(50, 0, 0), obstacle), InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping

namespace mmm::wrapping {
namespace {

// An insertion moving into the obstacle (every shape): the obstacle shrinks
// to keep it just outside, so the length changes smoothly; OpenSim's
// straight segment jumps by the wrap's detour.
TEST(ObstacleSetTest, AnEndPointMovingInsideShrinksTheObstacleAndKeepsTheLengthContinuous) {
  Obstacle cylinder;
  cylinder.shape = ObstacleShape::kCylinder;
  cylinder.radius = 20.0;
  Obstacle ellipsoid;
  ellipsoid.shape = ObstacleShape::kEllipsoid;
  ellipsoid.radii = Eigen::Vector3d(20.0, 25.0, 30.0);
  Obstacle sphere;
  sphere.radius = 20.0;
  for (const Obstacle& obstacle : {sphere, cylinder, ellipsoid}) {
    const Eigen::Vector3d p(-60.0, 5.0, 3.0);
    std::vector<double> lengths;
    bool went_inside = false;
    // S from 40 mm out to 10 mm from the centre, 0.1 mm at a time.
    for (double x = 40.0; x >= 10.0; x -= 0.1) {
      const WrapResult result = wrap_segment(p, Eigen::Vector3d(x, -4.0, 0.0), obstacle);
      went_inside = went_inside || result.inside;
      lengths.push_back(result.length);
    }
    EXPECT_TRUE(went_inside);
    // The length changes by at most ~0.1 mm a step (it is continuous), and
    // so does its rate (the analogue of a moment arm: no kink where the
    // shrinking starts).
    double largest_step = 0.0;
    double largest_rate_change = 0.0;
    for (std::size_t i = 1; i < lengths.size(); ++i) {
      largest_step = std::max(largest_step, std::abs(lengths[i] - lengths[i - 1]));
      if (i >= 2) {
        const double rate = (lengths[i] - lengths[i - 1]) / 0.1;
        const double before = (lengths[i - 1] - lengths[i - 2]) / 0.1;
        largest_rate_change = std::max(largest_rate_change, std::abs(rate - before));
      }
    }
    const int shape = static_cast<int>(obstacle.shape);
    EXPECT_LT(largest_step, 0.25) << "shape " << shape;
    EXPECT_LT(largest_rate_change, 0.1) << "shape " << shape;
    WrapOptions opensim;
    opensim.shrink_to_inside_points = false;
    const WrapResult outside = wrap_segment(p, Eigen::Vector3d(20.5, -4.0, 0.0), obstacle, opensim);
    const WrapResult in = wrap_segment(p, Eigen::Vector3d(19.0, -4.0, 0.0), obstacle, opensim);
    EXPECT_TRUE(in.inside);
    EXPECT_FALSE(in.wrapped);
    EXPECT_GT(outside.length - in.length, 1.0);  // the jump the default avoids
  }
}

}  // namespace
}  // namespace mmm::wrapping

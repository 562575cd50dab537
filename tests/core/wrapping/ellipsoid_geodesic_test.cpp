// Ellipsoid obstacles in the obstacle-set method: equal radii against the
// sphere's closed form, a prolate ellipsoid against the bounds its inscribed
// and circumscribed spheres give and against the geometry of a shortest
// path (on the surface, a geodesic there, tangent straight parts), and an
// ellipsoid riding on the toy leg's femur in an action line.

#include "core/wrapping/ellipsoid_geodesic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/motion/skeleton.h"
#include "core/wrapping/action_line_path.h"
#include "core/wrapping/obstacle_set.h"
#include "tests/support/test_helpers.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::wrapping {
namespace {

using Eigen::Vector3d;

using test::tilted_pose;

Obstacle ellipsoid_at(const Eigen::Isometry3d& pose, const Vector3d& radii) {
  Obstacle obstacle;
  obstacle.shape = ObstacleShape::kEllipsoid;
  obstacle.pose = pose;
  obstacle.radii = radii;
  return obstacle;
}

Obstacle geodesic_sphere_at(const Eigen::Isometry3d& pose, double radius) {
  Obstacle obstacle;
  obstacle.pose = pose;
  obstacle.radius = radius;
  return obstacle;
}

// sum (x_i / r_i)^2 - 1 of a world point: 0 on the surface, > 0 outside.
double implicit(const Obstacle& ellipsoid, const Vector3d& world) {
  return (ellipsoid.pose.inverse() * world).cwiseQuotient(ellipsoid.radii).squaredNorm() - 1.0;
}

// Outward unit normal at a world point on the surface.
Vector3d normal_at(const Obstacle& ellipsoid, const Vector3d& world) {
  const Vector3d local = ellipsoid.pose.inverse() * world;
  const Vector3d squares = ellipsoid.radii.cwiseProduct(ellipsoid.radii);
  return (ellipsoid.pose.linear() * local.cwiseQuotient(squares)).normalized();
}

TEST(EllipsoidGeodesicTest, EqualRadiiGiveTheSpheresGreatCircle) {
  const Eigen::Isometry3d pose = tilted_pose(Vector3d(10, 20, 30));
  const Vector3d p = pose.translation() + Vector3d(-80, -20, 10);
  const Vector3d s = pose.translation() + Vector3d(90, -25, -5);
  for (const char* quadrant : {"all", "+y"}) {
    Obstacle ellipsoid = ellipsoid_at(pose, Vector3d(40, 40, 40));
    Obstacle sphere = geodesic_sphere_at(pose, 40.0);
    ellipsoid.quadrant = sphere.quadrant = quadrant;
    const WrapResult numeric = wrap_segment(p, s, ellipsoid);
    const WrapResult exact = wrap_segment(p, s, sphere);
    ASSERT_TRUE(numeric.wrapped) << quadrant;
    ASSERT_TRUE(exact.wrapped) << quadrant;
    // The relaxation starts on the exact great circle and the chords' arcs
    // are exact to O(h^4): measured ~1e-9 relative; the brief asks 1e-3.
    EXPECT_NEAR(numeric.length, exact.length, 1e-6 * exact.length) << quadrant;
    // Between normals at the discrete ends, which sit up to ~0.07 mm off the
    // exact tangent points (the straight parts meet the first and last 2 mm
    // chords, not the circle's tangents): measured 1e-3 and 3.5e-3 rad.
    EXPECT_NEAR(numeric.wrap_angle, exact.wrap_angle, 1e-2) << quadrant;
    // Tangent points: the discrete path's ends sit within a fraction of a
    // 2 mm step of the exact ones.
    EXPECT_LT((numeric.tangent_in - exact.tangent_in).norm(), 0.5) << quadrant;
    EXPECT_LT((numeric.tangent_out - exact.tangent_out).norm(), 0.5) << quadrant;
  }
}

TEST(EllipsoidGeodesicTest, AProlateWrapIsAShortestPathBetweenItsSpheresBounds) {
  const Vector3d radii(25, 25, 60);
  const Obstacle ellipsoid = ellipsoid_at(tilted_pose(Vector3d(5, -7, 100)), radii);
  const Vector3d p = ellipsoid.pose * Vector3d(-90, -8, 40);
  const Vector3d s = ellipsoid.pose * Vector3d(95, -6, -45);
  WrapOptions fine;
  fine.arc_step_mm = 0.5;
  const WrapResult wrap = wrap_segment(p, s, ellipsoid, fine);
  ASSERT_TRUE(wrap.wrapped);
  EXPECT_FALSE(wrap.inside);
  // Outside the inscribed sphere (r 25) and inside the circumscribed one
  // (r 60), both of which the straight line crosses: the shortest paths
  // around them bound this one.
  const WrapResult inner = wrap_segment(p, s, geodesic_sphere_at(ellipsoid.pose, radii.minCoeff()));
  const WrapResult outer = wrap_segment(p, s, geodesic_sphere_at(ellipsoid.pose, radii.maxCoeff()));
  ASSERT_TRUE(inner.wrapped);
  ASSERT_TRUE(outer.wrapped);
  EXPECT_GT(wrap.length, inner.length);
  EXPECT_LT(wrap.length, outer.length);
  EXPECT_GT(wrap.length, (s - p).norm());
  // The wrapped part lies on the surface, every 0.5 mm at most.
  ASSERT_GT(wrap.points.size(), 10u);
  for (std::size_t i = 1; i + 1 < wrap.points.size(); ++i) {
    EXPECT_NEAR(implicit(ellipsoid, wrap.points[i]), 0.0, 1e-12);
    if (i > 1) {
      EXPECT_LE((wrap.points[i] - wrap.points[i - 1]).norm(), 0.5 + 1e-9);
    }
  }
  // A geodesic: the path bends only along the surface normal. The discrete
  // curvature x_{i-1} + x_{i+1} - 2 x_i has no tangential part but for
  // uneven spacing (measured < 1e-3 of it).
  for (std::size_t i = 2; i + 2 < wrap.points.size(); ++i) {
    const Vector3d bend = wrap.points[i - 1] + wrap.points[i + 1] - 2.0 * wrap.points[i];
    const Vector3d normal = normal_at(ellipsoid, wrap.points[i]);
    EXPECT_LT((bend - bend.dot(normal) * normal).norm(), 1e-2 * bend.norm()) << i;
    EXPECT_LT(bend.dot(normal), 0.0) << i;  // it bends around the surface
  }
  // The straight parts stay off the surface and meet it tangentially: the
  // angle between them and the tangent plane is about half a step's turn
  // (0.5 mm at curvature <= 60 / 25^2: ~0.05 rad at most).
  const Vector3d in = (wrap.tangent_in - p).normalized();
  const Vector3d out = (s - wrap.tangent_out).normalized();
  EXPECT_LT(std::abs(in.dot(normal_at(ellipsoid, wrap.tangent_in))), 0.05);
  EXPECT_LT(std::abs(out.dot(normal_at(ellipsoid, wrap.tangent_out))), 0.05);
  for (double t = 0.0; t < 1.0; t += 0.01) {
    EXPECT_GT(implicit(ellipsoid, p + t * (wrap.tangent_in - p)), -1e-9);
    EXPECT_GT(implicit(ellipsoid, wrap.tangent_out + t * (s - wrap.tangent_out)), -1e-9);
  }
  // Finer steps converge: the 2 mm default is within 1e-4 of 0.5 mm.
  const WrapResult coarse = wrap_segment(p, s, ellipsoid);
  EXPECT_NEAR(coarse.length, wrap.length, 1e-4 * wrap.length);
}

TEST(EllipsoidGeodesicTest, MissesStayStraightInsidePointsAreFlaggedBadRadiiAreErrors) {
  const Obstacle ellipsoid = ellipsoid_at(tilted_pose(Vector3d::Zero()), Vector3d(10, 20, 30));
  const WrapResult miss = wrap_segment(Vector3d(-100, 0, 60), Vector3d(100, 0, 60), ellipsoid);
  EXPECT_FALSE(miss.wrapped);
  EXPECT_DOUBLE_EQ(miss.length, 200.0);
  const WrapResult inside = wrap_segment(Vector3d(1, 1, 1), Vector3d(100, 0, 0), ellipsoid);
  EXPECT_TRUE(inside.inside);
  EXPECT_FALSE(inside.wrapped);
  Obstacle flat = ellipsoid;
  flat.radii = Vector3d(10, 0, 30);
  EXPECT_THROW(wrap_segment(Vector3d(-100, 0, 0), Vector3d(100, 0, 0), flat), InvalidInputError);
  Obstacle sided = ellipsoid;
  sided.quadrant = "-z";  // an ellipsoid, like a sphere, has a z side
  EXPECT_TRUE(wrap_segment(Vector3d(-100, 0, 0), Vector3d(100, 0, 0), sided).wrapped);
  sided.quadrant = "+w";
  EXPECT_THROW(wrap_segment(Vector3d(-100, 0, 0), Vector3d(100, 0, 0), sided), InvalidInputError);
}

TEST(EllipsoidGeodesicTest, AnEllipsoidOnTheFemurBendsAnActionLineSmoothly) {
  test::ToyLeg leg = test::toy_leg();
  atlas::Muscle& muscle = leg.atlas.muscles.front();
  atlas::WrapObstacle& ball = muscle.wrap_obstacles.front();
  ball.shape = atlas::WrapShape::kEllipsoid;
  ball.radii = Vector3d(25, 18, 40);
  const Vector3d from(100, 5, -150);
  const Vector3d to(90, 30, -480);
  ball.pose.translation() = 0.5 * (from + to) - Vector3d(0, 10, 0);
  muscle.action_lines.front().wrap_obstacles = {ball.name};
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(leg.atlas);
  const Eigen::VectorXd q = skeleton.default_coordinates();
  const atlas::ActionLine& line = muscle.action_lines.front();
  const ActionLinePath path = action_line_path(leg.atlas, muscle, line, skeleton, q);
  EXPECT_EQ(path.wraps, 1);
  EXPECT_GT(path.length, (path.points.back() - path.points.front()).norm());
  // The same as wrapping the posed segment directly.
  motion::SkeletonPose pose(skeleton);
  pose.set(q);
  Obstacle posed =
      ellipsoid_at(pose.body_pose(*skeleton.body_index("femur_r")) * ball.pose, ball.radii);
  const WrapResult direct =
      wrap_segment(path.points.front(), path.points.back(), posed, PathOptions{}.wrap);
  EXPECT_NEAR(path.length, direct.length, 1e-9);
  // Moment arms by central differences need a length smooth in the pose:
  // steps 1e-4 and 1e-3 rad agree (the difference is h^2 L''' / 6, ~1e-6).
  const int knee = *skeleton.coordinate_index("knee_angle_r");
  PathOptions small;
  PathOptions large;
  large.derivative_step = 1e-3;
  const double arm = moment_arm(leg.atlas, muscle, line, skeleton, q, knee, small);
  EXPECT_NEAR(arm, moment_arm(leg.atlas, muscle, line, skeleton, q, knee, large),
              1e-4 * (1.0 + std::abs(arm)));
}

}  // namespace
}  // namespace mmm::wrapping

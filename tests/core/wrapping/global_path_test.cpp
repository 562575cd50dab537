// Global paths over meshes against the obstacle-set method's closed forms
// on the same shapes: a sphere (great circle) and a cylinder (helix), each
// inflated by the clearance; straight lines that miss, warm starts, ends
// inside a bone, bad input.

#include "core/wrapping/global_path.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "core/wrapping/obstacle_set.h"
#include "tests/support/test_helpers.h"

namespace mmm::wrapping {
namespace {

using Eigen::Vector3d;
using ::testing::HasSubstr;

constexpr double kObstacleRadius = 30.0;
constexpr double kClearance = 1.0;

// An icosphere of 20480 faces: its flat faces lie up to ~0.006 mm inside the
// sphere through its vertices (triangles of circumradius ~0.6 mm on 30 mm).
const mesh::SignedDistance& sphere_sdf() {
  static const mesh::SignedDistance sdf(mesh::make_icosphere(5, kObstacleRadius));
  return sdf;
}

// A closed cylinder of radius 30 along z, 300 mm long, centred on its frame's
// origin; 256 sides, whose flat faces lie 30 (1 - cos(pi / 256)) ~ 0.002 mm
// inside the circle.
const mesh::SignedDistance& cylinder_sdf() {
  static const mesh::SignedDistance sdf = [] {
    mesh::IndexedMesh mesh = mesh::make_cylinder(kObstacleRadius, 300.0, 256);
    mesh.V.col(2).array() -= 150.0;
    return mesh::SignedDistance(mesh);
  }();
  return sdf;
}

using test::polyline_length;
using test::tilted_pose;

TEST(GlobalPathTest, AStraightSegmentThatMissesTheObstacleStaysStraight) {
  const PosedSurface sphere{&sphere_sdf(), tilted_pose(Vector3d(10, 20, 30))};
  const Vector3d a = sphere.pose * Vector3d(-100, 45, 0);
  const Vector3d b = sphere.pose * Vector3d(100, 45, 0);
  const GlobalSegment segment = global_segment(a, b, {sphere});
  // 1e-6: only rounding in the 40 chords of a 200 mm line.
  EXPECT_NEAR(segment.length, 200.0, 1e-6);
  EXPECT_EQ(segment.iterations, 0);
  EXPECT_FALSE(segment.touches);
  EXPECT_DOUBLE_EQ(segment.max_penetration, -kClearance);
  ASSERT_GT(segment.points.size(), 2u);
  for (const Vector3d& point : segment.points) {
    EXPECT_NEAR((point - a).cross(b - a).norm() / (b - a).norm(), 0.0, 1e-9);
  }
  EXPECT_EQ(segment.surfaces, std::vector<int>{0});
}

TEST(GlobalPathTest, ASegmentThroughASphereMeshWrapsAlongTheGreatCircle) {
  const PosedSurface sphere{&sphere_sdf(), tilted_pose(Vector3d(10, 20, 30))};
  const Vector3d c = sphere.pose.translation();
  // Ends close to the sphere on either side: a wrap of ~85 degrees.
  const Vector3d a = c + Vector3d(-40, -5, 3);
  const Vector3d b = c + Vector3d(40, -6, -2);
  const GlobalSegment segment = global_segment(a, b, {sphere});
  Obstacle inflated;
  inflated.pose = sphere.pose;
  inflated.radius = kObstacleRadius + kClearance;
  const WrapResult analytic = wrap_segment(a, b, inflated);
  ASSERT_TRUE(analytic.wrapped);
  EXPECT_TRUE(segment.converged);
  EXPECT_TRUE(segment.touches);
  EXPECT_GT(segment.iterations, 0);
  // Points every <= 5 mm: chords on the 31 mm circle fall short of its arcs
  // by h^2 / (24 r^2) ~ 1e-3 of the wrapped part, half the path here
  // (measured: -6e-4 of the whole); the facets add ~0.006 mm.
  EXPECT_NEAR(segment.length, analytic.length, 2e-3 * analytic.length);
  EXPECT_NEAR(segment.length, polyline_length(segment.points), 1e-9);
  EXPECT_GT(segment.length, (b - a).norm() + 5.0);
  EXPECT_GT(analytic.wrap_angle, 1.2);
  // Clear of the sphere by the clearance, but for the facets (~0.006 mm).
  for (const Vector3d& point : segment.points) {
    EXPECT_GE((point - c).norm(), kObstacleRadius + kClearance - 1e-2);
  }
  EXPECT_NEAR(segment.max_penetration, -kClearance, 1e-6);
}

TEST(GlobalPathTest, ASegmentAcrossACylinderMeshWrapsAlongTheHelix) {
  const PosedSurface cylinder{&cylinder_sdf(), tilted_pose(Vector3d(5, -7, 100))};
  const Vector3d a = cylinder.pose * Vector3d(-60, -25, -40);
  const Vector3d b = cylinder.pose * Vector3d(70, -20, 55);
  const GlobalSegment segment = global_segment(a, b, {cylinder});
  Obstacle inflated;
  inflated.shape = ObstacleShape::kCylinder;
  inflated.pose = cylinder.pose;
  inflated.radius = kObstacleRadius + kClearance;
  const WrapResult analytic = wrap_segment(a, b, inflated);
  ASSERT_TRUE(analytic.wrapped);
  EXPECT_TRUE(segment.converged);
  EXPECT_TRUE(segment.touches);
  // As for the sphere: chords on a 31 mm circle (the helix is straight once
  // unrolled, so only its xy part bends).
  EXPECT_NEAR(segment.length, analytic.length, 1e-3 * analytic.length);
  // Clear of the cylinder by the clearance, but for the facets (0.0023 mm).
  const Eigen::Isometry3d to_local = cylinder.pose.inverse();
  for (const Vector3d& point : segment.points) {
    EXPECT_GE((to_local * point).head<2>().norm(), kObstacleRadius + kClearance - 3e-3);
  }
}

TEST(GlobalPathTest, AWarmStartFromThePreviousFrameConvergesInFewerIterations) {
  const PosedSurface sphere{&sphere_sdf(), tilted_pose(Vector3d(10, 20, 30))};
  const Vector3d c = sphere.pose.translation();
  const Vector3d a = c + Vector3d(-80, -20, 10);
  const GlobalSegment previous = global_segment(a, c + Vector3d(90, -25, -5), {sphere});
  // The next frame: the insertion moved by 2 mm.
  const Vector3d b = c + Vector3d(91, -23, -4);
  const GlobalSegment cold = global_segment(a, b, {sphere});
  const GlobalSegment warm = global_segment(a, b, {sphere}, {}, previous.points);
  EXPECT_TRUE(warm.converged);
  EXPECT_GT(warm.iterations, 0);
  EXPECT_LT(warm.iterations, cold.iterations);
  // The same path: both converge to the solver's tolerance, on the same
  // number of points.
  EXPECT_NEAR(warm.length, cold.length, 1e-4);
}

TEST(GlobalPathTest, AFixedPointInsideASurfaceIsReportedAndThePathLeavesItAlongTheGradient) {
  const PosedSurface sphere{&sphere_sdf(), tilted_pose(Vector3d(10, 20, 30))};
  const Vector3d c = sphere.pose.translation();
  const Vector3d inside = c + Vector3d(0, 12, 0);
  const Vector3d outside = c + Vector3d(20, 90, 0);
  const GlobalSegment segment = global_segment(inside, outside, {sphere});
  EXPECT_TRUE(segment.start_inside);
  EXPECT_FALSE(segment.end_inside);
  EXPECT_TRUE(segment.touches);
  for (const Vector3d& point : segment.points) EXPECT_TRUE(point.allFinite());
  // The lift: radially out to the inflated sphere (the icosphere's facets
  // are within ~0.005 mm of it).
  ASSERT_GE(segment.points.size(), 3u);
  EXPECT_NEAR((segment.points[1] - c).norm(), kObstacleRadius + kClearance, 1e-2);
  EXPECT_NEAR((segment.points[1] - c).normalized().dot((inside - c).normalized()), 1.0, 1e-4);
  EXPECT_GE(segment.length, (outside - inside).norm());
  // Whole paths report it too, at the segment that starts there.
  const GlobalPath path = global_path({outside, inside, outside}, {sphere});
  ASSERT_EQ(path.segments.size(), 2u);
  EXPECT_TRUE(path.segments[0].end_inside);
  EXPECT_TRUE(path.segments[1].start_inside);
}

TEST(GlobalPathTest, AWholePathIsItsSegmentsEndToEnd) {
  const PosedSurface sphere{&sphere_sdf(), tilted_pose(Vector3d(10, 20, 30))};
  const Vector3d c = sphere.pose.translation();
  const std::vector<Vector3d> fixed = {c + Vector3d(-80, -20, 10), c + Vector3d(90, -25, -5),
                                       c + Vector3d(90, 60, 0)};
  const GlobalPath path = global_path(fixed, {sphere});
  ASSERT_EQ(path.segments.size(), 2u);
  EXPECT_TRUE(path.segments[0].touches);
  EXPECT_FALSE(path.segments[1].touches);
  EXPECT_NEAR(path.length, path.segments[0].length + path.segments[1].length, 1e-9);
  EXPECT_NEAR(path.length, polyline_length(path.points), 1e-9);
  EXPECT_EQ(path.points.size(),
            path.segments[0].points.size() + path.segments[1].points.size() - 1);
  EXPECT_EQ(path.points.front(), fixed.front());
  EXPECT_EQ(path.points.back(), fixed.back());
  // Warm from itself: the same path again (resampled, so to the solver's
  // tolerance: ~1e-4 mm measured); a warm start for another number of
  // segments is ignored (the same cold solve).
  const GlobalPath again = global_path(fixed, {sphere}, {}, &path);
  EXPECT_NEAR(again.length, path.length, 1e-3);
  const GlobalPath other = global_path({fixed[0], fixed[1]}, {sphere}, {}, &path);
  EXPECT_DOUBLE_EQ(other.length, path.segments[0].length);
}

TEST(GlobalPathTest, OnlySurfacesNearTheSegmentAreQueried) {
  const PosedSurface near{&sphere_sdf(), tilted_pose(Vector3d(0, 0, 0))};
  const PosedSurface far{&sphere_sdf(), Eigen::Isometry3d(Eigen::Translation3d(500, 0, 0))};
  const std::vector<Vector3d> line = {Vector3d(-100, 0, 0), Vector3d(100, 0, 0)};
  EXPECT_EQ(surfaces_near(line, {near, far}, 10.0), std::vector<int>{0});
  // The far sphere's box (~[470, 530] in x) is 370 mm from the line's end.
  EXPECT_EQ(surfaces_near(line, {near, far}, 380.0), (std::vector<int>{0, 1}));
  const Eigen::AlignedBox3d box = world_bounds(far);
  EXPECT_TRUE(box.contains(Vector3d(500, 0, 0)));
  EXPECT_GT(box.sizes().minCoeff(), 2.0 * kObstacleRadius - 1e-9);
  const GlobalSegment segment = global_segment(line[0], line[1], {near, far});
  EXPECT_EQ(segment.surfaces, std::vector<int>{0});
  EXPECT_TRUE(segment.touches);
}

TEST(GlobalPathTest, NonFiniteOrMissingInputIsAnErrorThatNamesIt) {
  const PosedSurface sphere{&sphere_sdf(), Eigen::Isometry3d::Identity()};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  try {
    (void)global_path({Vector3d(-50, 0, 0), Vector3d(nan, 0, 0), Vector3d(50, 0, 0)}, {sphere});
    ADD_FAILURE() << "a NaN fixed point was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("fixed point 1 is not finite"));
  }
  try {
    (void)global_path({Vector3d(-50, 0, 0), Vector3d(50, 0, 0)}, {sphere, PosedSurface{}});
    ADD_FAILURE() << "a surface without a signed distance was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("surface 1"));
  }
  EXPECT_THROW((void)global_path({Vector3d(-50, 0, 0)}, {sphere}), InvalidInputError);
  GlobalPathOptions options;
  options.max_spacing_mm = 0.0;
  EXPECT_THROW((void)global_segment(Vector3d(-50, 0, 0), Vector3d(50, 0, 0), {sphere}, options),
               InvalidInputError);
  const std::vector<Vector3d> warm = {Vector3d(-50, 0, 0), Vector3d(0, nan, 0), Vector3d(50, 0, 0)};
  EXPECT_THROW((void)global_segment(Vector3d(-50, 0, 0), Vector3d(50, 0, 0), {sphere}, {}, warm),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping

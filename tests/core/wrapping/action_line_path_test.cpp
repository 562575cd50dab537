// Action-line paths on a moving skeleton: the toy leg's knee extensor, its
// length and its moment arm about the knee against the analytic
// derivative, and a wrap over an obstacle riding on the femur.

#include "core/wrapping/action_line_path.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>

#include "core/errors.h"
#include "core/motion/skeleton.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::wrapping {
namespace {

using Eigen::Vector3d;

TEST(ActionLinePathTest, MomentArmAboutAPinJointIsTheAnalyticDerivative) {
  test::ToyLeg leg = test::toy_leg();
  atlas::Muscle& muscle = leg.atlas.muscles.front();
  muscle.action_lines.front().wrap_obstacles.clear();  // straight: the analytic case
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(leg.atlas);
  const int knee = *skeleton.coordinate_index("knee_angle_r");
  const int femur = *skeleton.body_index("femur_r");
  for (const double angle : {0.0, 0.3, -0.5}) {
    Eigen::VectorXd q = skeleton.default_coordinates();
    q(knee) = angle;
    const ActionLinePath path =
        action_line_path(leg.atlas, muscle, muscle.action_lines.front(), skeleton, q);
    ASSERT_EQ(path.points.size(), 2u);
    const Vector3d a = path.points.front();  // on the femur
    const Vector3d b = path.points.back();   // on the tibia, turning about the knee
    EXPECT_NEAR(path.length, (b - a).norm(), 1e-12);
    // The pin turns the tibia about the joint frame's z axis through the
    // knee centre: dL/dq = (b - a)/L . (axis x (b - centre)).
    motion::SkeletonPose pose(skeleton);
    pose.set(q);
    const atlas::Joint& joint = *leg.atlas.find_joint("knee_r");
    const Eigen::Isometry3d frame = pose.body_pose(femur) * joint.parent_frame;
    const Vector3d axis = frame.linear() * Vector3d::UnitZ();
    const double analytic = -(b - a).normalized().dot(axis.cross(b - frame.translation()));
    // Central differences with a 1e-4 rad step: error ~h^2 L''' ~ 1e-8 mm.
    EXPECT_NEAR(moment_arm(leg.atlas, muscle, muscle.action_lines.front(), skeleton, q, knee),
                analytic, 1e-6)
        << angle;
  }
}

TEST(ActionLinePathTest, AnObstacleOnTheFemurBendsThePathAroundIt) {
  test::ToyLeg leg = test::toy_leg();
  atlas::Muscle& muscle = leg.atlas.muscles.front();
  atlas::WrapObstacle& ball = muscle.wrap_obstacles.front();
  ball.radii = Vector3d(25, 0, 0);
  // Put the ball right on the straight line's midpoint, shifted back a
  // little: the line must go around it.
  const Vector3d from(100, 5, -150);
  const Vector3d to(90, 30, -480);
  ball.pose.translation() = 0.5 * (from + to) - Vector3d(0, 10, 0);
  muscle.action_lines.front().wrap_obstacles = {ball.name};
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(leg.atlas);
  const Eigen::VectorXd q = skeleton.default_coordinates();
  const ActionLinePath path =
      action_line_path(leg.atlas, muscle, muscle.action_lines.front(), skeleton, q);
  EXPECT_EQ(path.wraps, 1);
  EXPECT_GT(path.points.size(), 4u);
  // The path's length is the obstacle-set answer for the same posed
  // segment and obstacle.
  motion::SkeletonPose pose(skeleton);
  pose.set(q);
  Obstacle posed;
  posed.pose = pose.body_pose(*skeleton.body_index("femur_r")) * ball.pose;
  posed.radius = 25;
  const WrapResult direct =
      wrap_segment(path.points.front(), path.points.back(), posed, PathOptions{}.wrap);
  EXPECT_NEAR(path.length, direct.length, 1e-9);
  EXPECT_GT(path.length, (path.points.back() - path.points.front()).norm());
}

TEST(ActionLinePathTest, UnknownObstaclesAndDegenerateEllipsoidsAreErrors) {
  test::ToyLeg leg = test::toy_leg();
  atlas::Muscle& muscle = leg.atlas.muscles.front();
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(leg.atlas);
  const Eigen::VectorXd q = skeleton.default_coordinates();
  muscle.action_lines.front().wrap_obstacles = {"no_such_obstacle"};
  EXPECT_THROW(action_line_path(leg.atlas, muscle, muscle.action_lines.front(), skeleton, q),
               InvalidInputError);
  muscle.action_lines.front().wrap_obstacles = {muscle.wrap_obstacles.front().name};
  muscle.wrap_obstacles.front().shape = atlas::WrapShape::kEllipsoid;
  muscle.wrap_obstacles.front().radii = Eigen::Vector3d(20, 0, 10);  // a zero semi-axis
  EXPECT_THROW(action_line_path(leg.atlas, muscle, muscle.action_lines.front(), skeleton, q),
               InvalidInputError);
  muscle.wrap_obstacles.front().radii = Eigen::Vector3d(20, 15, 10);  // a proper ellipsoid
  EXPECT_NO_THROW(action_line_path(leg.atlas, muscle, muscle.action_lines.front(), skeleton, q));
}

}  // namespace
}  // namespace mmm::wrapping

namespace mmm::wrapping {
namespace {

// A point added by the atlas build to keep a line inside its muscle follows
// the segment between the line's other points: same fraction along it, its
// offset turned with it. It bends the drawn path through the muscle; the
// length and the moment arms stay the line of action's.
TEST(ActionLinePathTest, AFollowerKeepsItsPlaceRelativeToTheSegmentAroundIt) {
  test::ToyLeg leg = test::toy_leg();
  atlas::Muscle& muscle = leg.atlas.muscles.front();
  atlas::ActionLine& line = muscle.action_lines.front();
  line.wrap_obstacles.clear();
  const Vector3d a0 = line.points.front().position;
  const Vector3d b0 = line.points.back().position;
  const Vector3d offset0 = (b0 - a0).cross(Vector3d::UnitX()).normalized() * 12.0;
  atlas::PathPoint follower;
  follower.name = "fit1";
  follower.bone = "femur_r";
  follower.kind = atlas::PathPointKind::kFollowsLine;
  follower.position = a0 + 0.4 * (b0 - a0) + offset0;
  line.points.insert(line.points.begin() + 1, follower);
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(leg.atlas);
  const int knee = *skeleton.coordinate_index("knee_angle_r");
  for (const double angle : {0.0, 0.4, -0.6}) {
    Eigen::VectorXd q = skeleton.default_coordinates();
    q(knee) = angle;
    const ActionLinePath path = action_line_path(leg.atlas, muscle, line, skeleton, q);
    ASSERT_EQ(path.points.size(), 3U);
    const Vector3d a = path.points[0];
    const Vector3d b = path.points[2];
    const Vector3d expected =
        a + 0.4 * (b - a) + Eigen::Quaterniond::FromTwoVectors(b0 - a0, b - a) * offset0;
    EXPECT_NEAR((path.points[1] - expected).norm(), 0.0, 1e-9) << angle;
    EXPECT_NEAR(path.length, (b - a).norm(), 1e-9) << angle;
    atlas::ActionLine straight = line;
    straight.points.erase(straight.points.begin() + 1);
    EXPECT_NEAR(moment_arm(leg.atlas, muscle, line, skeleton, q, knee),
                moment_arm(leg.atlas, muscle, straight, skeleton, q, knee), 1e-9)
        << angle;
  }
}

}  // namespace
}  // namespace mmm::wrapping

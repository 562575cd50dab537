// Moment-arm sweeps on cases with a known answer: a line wrapped over a
// cylinder centred on the joint axis (a pulley: the moment arm is the
// radius), a conditional via point switching on (length and moment arm stay
// continuous; OpenSim's abrupt switch would jump), and the comparison of two
// sweeps.

#include "core/wrapping/moment_arm_sweep.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/motion/skeleton.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::wrapping {
namespace {

using Eigen::Vector3d;

constexpr double kToDeg = 180.0 / std::numbers::pi;

// The toy leg's knee turns the tibia about the vertical axis through the
// knee centre K. Origin on the femur and insertion on the tibia, 100 mm to
// either side of K: the straight line passes through the axis, so a
// cylinder of radius 30 about it always deflects it (on its +y side).
struct PulleyKnee {
  test::ToyLeg leg = test::toy_leg();
  Vector3d centre = leg.atlas.find_joint("knee_r")->parent_frame.translation();
  PulleyKnee() {
    atlas::Muscle& muscle = leg.atlas.muscles.front();
    atlas::ActionLine& line = muscle.action_lines.front();
    line.points.front().position = centre + Vector3d(-100, 0, 0);
    line.points.back().position = centre + Vector3d(100, 0, 0);
    atlas::WrapObstacle& pulley = muscle.wrap_obstacles.front();
    pulley.shape = atlas::WrapShape::kCylinder;
    pulley.pose = Eigen::Isometry3d::Identity();
    pulley.pose.translation() = centre;
    pulley.radii = Vector3d(30, 0, 0);
    pulley.quadrant = "+y";
    line.wrap_obstacles = {pulley.name};
  }
};

TEST(MomentArmSweepTest, ALineOverACylinderAboutTheJointAxisHasTheRadiusAsMomentArm) {
  const PulleyKnee knee;
  const atlas::Muscle& muscle = knee.leg.atlas.muscles.front();
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(knee.leg.atlas);
  const LineSweep sweep = sweep_line(knee.leg.atlas, muscle, muscle.action_lines.front(), skeleton,
                                     {"knee_angle_r", -20, 20}, 5.0);
  ASSERT_EQ(sweep.angles_deg.size(), 9U);
  for (std::size_t i = 0; i < sweep.angles_deg.size(); ++i) {
    // Turning the insertion about the axis winds the path onto the pulley:
    // its length changes by r dq, whatever the angle.
    EXPECT_NEAR(std::abs(sweep.moment_arm_mm[i]), 30.0, 1e-4) << sweep.angles_deg[i];
  }
  EXPECT_NEAR(std::abs(sweep.length_mm.back() - sweep.length_mm.front()), 30.0 * 40.0 / kToDeg,
              1e-3);
}

// A knee extensor with a conditional via point on the femur, 25 mm off the
// straight line, active for knee angles from 0.3 rad.
struct ConditionalKnee {
  test::ToyLeg leg = test::toy_leg();
  ConditionalKnee() {
    atlas::ActionLine& line = leg.atlas.muscles.front().action_lines.front();
    line.wrap_obstacles.clear();
    const Vector3d from = line.points.front().position;
    const Vector3d to = line.points.back().position;
    atlas::PathPoint via;
    via.name = "switching";
    via.bone = "femur_r";
    via.kind = atlas::PathPointKind::kConditional;
    via.coordinate = "knee_angle_r";
    via.range = {0.3, 2.0};
    via.position = 0.5 * (from + to) + Vector3d(0, 25, 0);
    line.points.insert(line.points.begin() + 1, via);
  }
};

TEST(MomentArmSweepTest, AConditionalPointSwitchingOnKeepsLengthAndMomentArmContinuous) {
  const ConditionalKnee knee;
  const atlas::Muscle& muscle = knee.leg.atlas.muscles.front();
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(knee.leg.atlas);
  const CoordinateSweep across{"knee_angle_r", 0.25 * kToDeg, 0.45 * kToDeg};
  const LineSweep faded =
      sweep_line(knee.leg.atlas, muscle, muscle.action_lines.front(), skeleton, across, 0.05);
  // Sampled every 0.05 deg: the length changes at the rate of the moment arm
  // (< 2 mm/deg here) and the moment arm, fading in over 10 deg, at a
  // bounded rate.
  EXPECT_LT(largest_jump_per_deg(faded.angles_deg, faded.length_mm), 2.0);
  EXPECT_LT(largest_jump_per_deg(faded.angles_deg, faded.moment_arm_mm), 20.0);
  // The point is really used once faded in.
  EXPECT_GT(faded.length_mm.back() - faded.length_mm.front(), 1.0);

  PathOptions abrupt;
  abrupt.conditional_blend = 0.0;
  const LineSweep switched = sweep_line(knee.leg.atlas, muscle, muscle.action_lines.front(),
                                        skeleton, across, 0.05, abrupt);
  // Abruptly (OpenSim's switch): the length jumps where the point switches on.
  EXPECT_GT(largest_jump_per_deg(switched.angles_deg, switched.length_mm), 20.0);
}

TEST(MomentArmSweepTest, ComparisonsCountRmsSignsAndJumps) {
  LineSweep reference{"q", {0, 1, 2, 3}, {20, 12, -5, -15}, {100, 101, 102, 103}};
  LineSweep line = reference;
  EXPECT_DOUBLE_EQ(compare_sweeps(line, reference).rms_mm, 0.0);
  line.moment_arm_mm = {23, 15, -2, -12};
  SweepComparison c = compare_sweeps(line, reference);
  EXPECT_NEAR(c.rms_mm, 3.0, 1e-12);
  EXPECT_NEAR(c.max_abs_mm, 3.0, 1e-12);
  EXPECT_EQ(c.sign_checked, 3);  // |20|, |12|, |-15| exceed 10 mm
  EXPECT_EQ(c.sign_disagrees, 0);
  line.moment_arm_mm = {23, -15, -2, -12};
  c = compare_sweeps(line, reference);
  EXPECT_EQ(c.sign_disagrees, 1);
  EXPECT_NEAR(c.max_arm_jump_mm_per_deg, 38.0, 1e-12);
  EXPECT_NEAR(c.max_length_jump_mm_per_deg, 1.0, 1e-12);
  line.angles_deg = {0, 1, 2, 4};
  EXPECT_THROW(static_cast<void>(compare_sweeps(line, reference)), InvalidInputError);
}

TEST(MomentArmSweepTest, AnUnknownCoordinateIsRefused) {
  const test::ToyLeg leg = test::toy_leg();
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(leg.atlas);
  const atlas::Muscle& muscle = leg.atlas.muscles.front();
  EXPECT_THROW(static_cast<void>(sweep_line(leg.atlas, muscle, muscle.action_lines.front(),
                                            skeleton, {"knee_flexion", 0, 10})),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping

#include "core/opensim/kinematics.h"

#include <gtest/gtest.h>

#include <numbers>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::opensim {
namespace {

Body body_named(const std::string& name, bool is_ground = false) {
  Body body;
  body.name = name;
  body.is_ground = is_ground;
  return body;
}

Coordinate coordinate_named(const std::string& name) {
  Coordinate coordinate;
  coordinate.name = name;
  return coordinate;
}

FrameRef offset_frame(const std::string& body, const Eigen::Vector3d& translation) {
  FrameRef frame;
  frame.name = body + "_offset";
  frame.body = body;
  frame.translation = translation;
  return frame;
}

// Two bodies on a pin joint whose parent frame sits 1 m up the ground's y.
OsimModel pin_model() {
  OsimModel model;
  model.bodies.push_back(body_named("ground", true));
  model.bodies.push_back(body_named("arm"));
  Joint pin;
  pin.name = "shoulder";
  pin.type = "PinJoint";
  pin.parent = offset_frame("ground", Eigen::Vector3d(0, 1, 0));
  pin.child = offset_frame("arm", Eigen::Vector3d(-0.5, 0, 0));
  pin.coordinates.push_back(coordinate_named("angle"));
  model.joints.push_back(pin);
  return model;
}

TEST(KinematicsTest, PinJointRotatesTheChildAboutTheParentFrameZ) {
  const OsimModel model = pin_model();
  const auto poses = body_poses(model, {{"angle", std::numbers::pi / 2}});
  // The arm's origin is 0.5 m along the arm's -x from the joint: rotated by
  // 90 degrees about z, the arm's x axis points along ground y.
  const Eigen::Vector3d origin = poses.at("arm").translation();
  // 1e-12: a few rounding errors of sin/cos of pi/2.
  EXPECT_NEAR(origin.x(), 0.0, 1e-12);
  EXPECT_NEAR(origin.y(), 1.5, 1e-12);
  EXPECT_TRUE(poses.at("arm").linear().isApprox(
      Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));
}

TEST(KinematicsTest, CustomJointRotationsAreBodyFixedAndTranslationsInTheParent) {
  Joint joint;
  joint.name = "j";
  joint.type = "CustomJoint";
  joint.coordinates = {coordinate_named("a"), coordinate_named("b")};
  joint.spatial_transform = {
      TransformAxis{"rotation1", {"a"}, Eigen::Vector3d::UnitZ(), LinearFunction{}},
      TransformAxis{"rotation2", {"b"}, Eigen::Vector3d::UnitX(), LinearFunction{}},
      TransformAxis{"rotation3", {}, Eigen::Vector3d::UnitY(), Constant{0.0}},
      TransformAxis{"translation1", {"a"}, Eigen::Vector3d::UnitX(), LinearFunction{2.0, 0.0}},
      TransformAxis{"translation2", {}, Eigen::Vector3d::UnitY(), Constant{0.25}},
      TransformAxis{"translation3", {}, Eigen::Vector3d::UnitZ(), Constant{0.0}}};
  const double a = 0.3;
  const double b = -0.7;
  const Eigen::Isometry3d motion = joint_motion(joint, {{"a", a}, {"b", b}});
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(b, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  // 1e-14: products of a few rotations in double precision.
  EXPECT_TRUE(motion.linear().isApprox(expected, 1e-14));
  EXPECT_TRUE(motion.translation().isApprox(Eigen::Vector3d(2 * a, 0.25, 0.0), 1e-14));
}

TEST(KinematicsTest, DisconnectedBodyIsAnError) {
  OsimModel model = pin_model();
  model.bodies.push_back(body_named("floating"));
  EXPECT_THROW(body_poses(model), InvalidInputError);
}

TEST(KinematicsTest, Gait2392DefaultPoseStacksTheLegBelowTheHip) {
  const OsimModel model = read_osim(test::gait2392_model());
  const auto poses = body_poses(model);
  ASSERT_EQ(poses.size(), model.bodies.size());
  const Eigen::Vector3d hip = poses.at("femur_r").translation();
  const Eigen::Vector3d knee = poses.at("tibia_r").translation();
  const Eigen::Vector3d ankle = poses.at("talus_r").translation();
  // Default pose: standing upright (y up in gait2392), the knee about 0.40 m
  // below the hip and the ankle about 0.43 m below the knee (the gait2392
  // generic model's segment lengths; 0.02 m covers the coupled knee
  // translations and the default pelvis tilt).
  EXPECT_NEAR(hip.y() - knee.y(), 0.40, 0.02);
  EXPECT_NEAR(knee.y() - ankle.y(), 0.43, 0.02);
  // The right leg lies on +z (OpenSim: z to the right).
  EXPECT_GT(hip.z(), poses.at("pelvis").translation().z());
}

TEST(KinematicsTest, Gait2392KneeFlexionFollowsItsCoupledTranslations) {
  const OsimModel model = read_osim(test::gait2392_model());
  const double flexion = -std::numbers::pi / 2;  // gait2392: knee_angle_r is negative in flexion
  const auto straight = body_poses(model, {{"knee_angle_r", 0.0}});
  const auto bent = body_poses(model, {{"knee_angle_r", flexion}});
  const Eigen::Isometry3d femur = straight.at("femur_r");
  const Eigen::Vector3d tibia_straight = femur.inverse() * straight.at("tibia_r").translation();
  const Eigen::Vector3d tibia_bent = femur.inverse() * bent.at("tibia_r").translation();
  // The knee's tibia origin moves with the spline-coupled translations: it
  // differs between 0 and 90 degrees by millimetres (gait2392's splines move
  // it by about 1-2 cm), and the tibia rotates by the flexion angle about z.
  const double moved = (tibia_bent - tibia_straight).norm();
  EXPECT_GT(moved, 0.002);
  EXPECT_LT(moved, 0.05);
  const Eigen::Matrix3d relative =
      straight.at("tibia_r").linear().transpose() * bent.at("tibia_r").linear();
  // 1e-9: the rotation is exactly about z by the coordinate value.
  EXPECT_NEAR(Eigen::AngleAxisd(relative).angle(), std::numbers::pi / 2, 1e-9);
}

}  // namespace
}  // namespace mmm::opensim

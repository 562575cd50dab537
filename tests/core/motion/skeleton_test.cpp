#include "core/motion/skeleton.h"

#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "core/opensim/kinematics.h"
#include "core/opensim/osim_model.h"
#include "tests/support/motion_fixtures.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::motion {
namespace {

Eigen::VectorXd random_pose(const Skeleton& skeleton, std::mt19937& random) {
  Eigen::VectorXd q = skeleton.default_coordinates();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int c = 0; c < skeleton.num_coordinates(); ++c) {
    const SkeletonCoordinate& coordinate = skeleton.coordinates[static_cast<std::size_t>(c)];
    q(c) = coordinate.lower + unit(random) * (coordinate.upper - coordinate.lower);
  }
  return q;
}

TEST(SkeletonTest, OsimSkeletonPlacesBodiesAsOpenSimKinematicsDoes) {
  const opensim::OsimModel model = opensim::read_osim(test::data_dir() / "gait2392" / "Pipelines" /
                                                      "reference" / "subject01_simbody.osim");
  const Skeleton skeleton = skeleton_from_osim(model);
  EXPECT_EQ(skeleton.bodies.size(), 12u);  // gait2392: every body but the ground
  EXPECT_EQ(skeleton.num_coordinates(), 23);
  EXPECT_EQ(skeleton.markers.size(), 39u);
  std::mt19937 random(3);
  SkeletonPose pose(skeleton);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd q = random_pose(skeleton, random);
    opensim::CoordinateValues values;
    for (int c = 0; c < skeleton.num_coordinates(); ++c) {
      const SkeletonCoordinate& coordinate = skeleton.coordinates[static_cast<std::size_t>(c)];
      values[coordinate.name] = coordinate.unit == CoordinateUnit::kLength ? q(c) / 1000 : q(c);
    }
    const auto reference = opensim::body_poses(model, values);
    pose.set(q);
    for (std::size_t b = 0; b < skeleton.bodies.size(); ++b) {
      const Eigen::Isometry3d& expected = reference.at(skeleton.bodies[b].name);
      const Eigen::Isometry3d& got = pose.body_pose(static_cast<int>(b));
      // Same formula in m and mm: agreement to rounding.
      EXPECT_LT((got.linear() - expected.linear()).norm(), 1e-12) << skeleton.bodies[b].name;
      EXPECT_LT((got.translation() - 1000.0 * expected.translation()).norm(), 1e-9)
          << skeleton.bodies[b].name;
    }
  }
}

TEST(SkeletonTest, JacobianMatchesCentralDifferences) {
  const Skeleton& skeleton = test::subject01_skeleton();
  std::mt19937 random(11);
  SkeletonPose pose(skeleton);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = random_pose(skeleton, random);
    const auto markers = static_cast<Eigen::Index>(skeleton.markers.size());
    Eigen::MatrixXd analytic = Eigen::MatrixXd::Zero(3 * markers, skeleton.num_coordinates());
    pose.set(q);
    for (Eigen::Index m = 0; m < markers; ++m) {
      const int body = skeleton.markers[static_cast<std::size_t>(m)].body;
      pose.add_point_jacobian(body, pose.marker(static_cast<int>(m)), 1.0, analytic, 3 * m);
    }
    Eigen::MatrixXd numeric(3 * markers, skeleton.num_coordinates());
    for (int c = 0; c < skeleton.num_coordinates(); ++c) {
      const double h =
          skeleton.coordinates[static_cast<std::size_t>(c)].unit == CoordinateUnit::kLength ? 1e-3
                                                                                            : 1e-6;
      Eigen::VectorXd plus = q;
      Eigen::VectorXd minus = q;
      plus(c) += h;
      minus(c) -= h;
      for (Eigen::Index m = 0; m < markers; ++m) {
        pose.set(plus);
        const Eigen::Vector3d a = pose.marker(static_cast<int>(m));
        pose.set(minus);
        numeric.block<3, 1>(3 * m, c) = (a - pose.marker(static_cast<int>(m))) / (2 * h);
      }
    }
    // Central differences of splines: truncation ~h^2 f''' (mm per rad); the
    // knee's coupled splines switch pieces within h only rarely.
    EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), 1e-4);
  }
}

TEST(SkeletonTest, AtlasSkeletonKeepsEveryBoneInPlaceAtRest) {
  const test::ToyLeg leg = test::toy_leg();
  const Skeleton skeleton = skeleton_from_atlas(leg.atlas);
  ASSERT_EQ(skeleton.bodies.front().name, "pelvis");
  EXPECT_EQ(skeleton.coordinates.front().name, "pelvis_tilt");
  Eigen::VectorXd rest = skeleton.default_coordinates();
  for (const atlas::Joint& joint : leg.atlas.joints) {
    for (const atlas::Coordinate& coordinate : joint.coordinates) {
      rest(*skeleton.coordinate_index(coordinate.name)) = coordinate.rest_value;
    }
  }
  // The root at the pelvis frame: pose = M(root) * frame^-1, so put the
  // root's coordinates where the frame is the identity map.
  SkeletonPose pose(skeleton);
  pose.set(rest);
  const Eigen::Isometry3d root = pose.body_pose(0);
  for (std::size_t b = 0; b < skeleton.bodies.size(); ++b) {
    // Relative to the root, every bone is exactly where the atlas has it.
    const Eigen::Isometry3d relative = root.inverse() * pose.body_pose(static_cast<int>(b));
    EXPECT_LT((relative.matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-9)
        << skeleton.bodies[b].name;
  }
  // Markers are the atlas's, on their bones.
  ASSERT_EQ(skeleton.markers.size(), leg.atlas.markers.size());
  EXPECT_EQ(skeleton.bodies[static_cast<std::size_t>(skeleton.markers[0].body)].name, "femur_r");
  EXPECT_LT((root.inverse() * pose.marker(0) - leg.atlas.markers[0].position).norm(), 1e-9);
}

TEST(SkeletonTest, RejectsBadCoordinates) {
  const Skeleton& skeleton = test::subject01_skeleton();
  SkeletonPose pose(skeleton);
  EXPECT_THROW(pose.set(Eigen::VectorXd::Zero(3)), InvalidInputError);
  Eigen::VectorXd q = skeleton.default_coordinates();
  q(5) = std::nan("");
  try {
    pose.set(q);
    FAIL() << "a NaN coordinate was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find(skeleton.coordinates[5].name), std::string::npos);
  }
}

}  // namespace
}  // namespace mmm::motion

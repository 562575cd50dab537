#include "core/atlas/opensim_mapping.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "core/errors.h"
#include "core/opensim/kinematics.h"
#include "core/opensim/osim_model.h"
#include "tests/support/test_data.h"

namespace mmm::atlas {
namespace {

// OpenSim ground (X forward, Y up, Z right) -> atlas (x right, y anterior,
// z superior): atlas x = Z, y = X, z = Y. A cyclic permutation: det +1.
Eigen::Matrix3d axis_permutation() {
  Eigen::Matrix3d p;
  p << 0, 0, 1,  //
      1, 0, 0,   //
      0, 1, 0;
  return p;
}

// The identity-like map every body gets: metres -> mm, axes permuted, moved.
Eigen::Affine3d base_map() {
  Eigen::Affine3d map = Eigen::Affine3d::Identity();
  map.linear() = 1000.0 * axis_permutation();
  map.translation() = Eigen::Vector3d(120, -40, 900);
  return map;
}

const opensim::OsimModel& gait2392() {
  static const opensim::OsimModel model =
      opensim::read_osim(test::data_dir() / "gait2392" / "gait2392_thelen2003muscle.osim");
  return model;
}

// Every body at the default pose, all with the same map; each body stands
// for an atlas bone of its own name.
BodyMaps identity_like_maps() {
  BodyMaps maps;
  maps.pose = opensim::body_poses(gait2392());
  for (const auto& [body, pose] : maps.pose) {
    maps.map[body] = base_map();
    maps.primary_bone[body] = body;
  }
  return maps;
}

// The hip joint's parent frame in the ground at the default pose (m).
Eigen::Isometry3d hip_parent_in_ground(const BodyMaps& maps, const opensim::Joint& hip) {
  return maps.pose.at(hip.parent.body) * opensim::frame_in_body(hip.parent);
}

// Turns `map` by `rotation` (atlas) about the atlas point `centre`.
Eigen::Affine3d turned_about(const Eigen::Affine3d& map, const Eigen::Matrix3d& rotation,
                             const Eigen::Vector3d& centre) {
  Eigen::Affine3d turn = Eigen::Affine3d::Identity();
  turn.linear() = rotation;
  turn.translation() = centre - rotation * centre;
  return turn * map;
}

double coordinate_rest(const Joint& joint, const std::string& name) {
  for (const Coordinate& coordinate : joint.coordinates) {
    if (coordinate.name == name) return coordinate.rest_value;
  }
  ADD_FAILURE() << "no coordinate " << name;
  return std::nan("");
}

TEST(OpenSimMappingTest, SameMapForAllBodiesGivesTheDefaultPose) {
  const BodyMaps maps = identity_like_maps();
  for (const opensim::Joint& source : gait2392().joints) {
    const MappedJoint mapped = map_joint(source, maps);
    // The mapped frames are the default pose's, so the defaults reproduce
    // them: Gauss-Newton stops at once, leaving rounding (1e-9 rad, 1e-6 mm
    // of metre-to-mm products).
    EXPECT_LT(mapped.mismatch_deg, 1e-6) << source.name;
    EXPECT_LT(mapped.mismatch_mm, 1e-6) << source.name;
    ASSERT_EQ(mapped.joint.coordinates.size(), source.coordinates.size());
    for (std::size_t k = 0; k < source.coordinates.size(); ++k) {
      const Coordinate& coordinate = mapped.joint.coordinates[k];
      const double unit = coordinate.kind == CoordinateKind::kTranslational ? 1000.0 : 1.0;
      EXPECT_NEAR(coordinate.rest_value, source.coordinates[k].default_value * unit, 1e-7)
          << coordinate.name;  // rad, or mm for translations
      EXPECT_NEAR(coordinate.default_value, source.coordinates[k].default_value * unit, 1e-12)
          << coordinate.name;
    }
  }
}

TEST(OpenSimMappingTest, HipFramesAndCoordinatesComeThrough) {
  const BodyMaps maps = identity_like_maps();
  const opensim::Joint* hip = gait2392().find_joint("hip_r");
  ASSERT_NE(hip, nullptr);
  const MappedJoint mapped = map_joint(*hip, maps);
  const Joint& joint = mapped.joint;
  EXPECT_EQ(joint.name, "hip_r");
  EXPECT_EQ(joint.type, JointType::kCustom);
  EXPECT_EQ(joint.parent, "pelvis");
  EXPECT_EQ(joint.child, "femur_r");
  ASSERT_EQ(joint.coordinates.size(), 3U);
  ASSERT_EQ(joint.axes.size(), 6U);
  // Hip rest values ~0: the default pose is the rest pose.
  for (const char* name : {"hip_flexion_r", "hip_adduction_r", "hip_rotation_r"}) {
    EXPECT_NEAR(coordinate_rest(joint, name), 0.0, 1e-9) << name;  // rounding, rad
  }
  EXPECT_EQ(joint.axes[0].coordinate, "hip_flexion_r");
  EXPECT_TRUE(joint.axes[0].rotation);
  EXPECT_FALSE(joint.axes[3].rotation);
  // The frames sit at the mapped hip centre, turned by the permutation.
  const Eigen::Isometry3d parent_ground = hip_parent_in_ground(maps, *hip);
  EXPECT_LT((joint.parent_frame.translation() - base_map() * parent_ground.translation()).norm(),
            1e-9);  // mm, rounding
  EXPECT_LT((joint.parent_frame.linear() - axis_permutation() * parent_ground.linear()).norm(),
            1e-12);
  EXPECT_LT((joint.child_frame.translation() - joint.parent_frame.translation()).norm(), 1e-9);
  EXPECT_NEAR(maps.scale("femur_r"), 1000.0, 1e-9);
}

TEST(OpenSimMappingTest, ChildTurnedAboutTheFlexionAxisGivesThatFlexion) {
  BodyMaps maps = identity_like_maps();
  const opensim::Joint* hip = gait2392().find_joint("hip_r");
  ASSERT_NE(hip, nullptr);
  ASSERT_EQ(hip->spatial_transform.front().coordinates.front(), "hip_flexion_r");
  // The flexion axis (rotation1, in the parent frame) and the hip centre,
  // both in the atlas.
  const Eigen::Isometry3d parent_ground = hip_parent_in_ground(maps, *hip);
  const Eigen::Vector3d axis =
      axis_permutation() * parent_ground.linear() * hip->spatial_transform.front().axis;
  const Eigen::Vector3d centre = base_map() * parent_ground.translation();
  const double flexion = 0.35;  // rad, 20 degrees
  maps.map["femur_r"] = turned_about(
      base_map(), Eigen::AngleAxisd(flexion, axis.normalized()).toRotationMatrix(), centre);

  const MappedJoint mapped = map_joint(*hip, maps);
  // An exact pose of the joint's motion: Gauss-Newton converges to rounding.
  EXPECT_NEAR(coordinate_rest(mapped.joint, "hip_flexion_r"), flexion, 1e-7);
  EXPECT_NEAR(coordinate_rest(mapped.joint, "hip_adduction_r"), 0.0, 1e-7);
  EXPECT_NEAR(coordinate_rest(mapped.joint, "hip_rotation_r"), 0.0, 1e-7);
  EXPECT_LT(mapped.mismatch_deg, 1e-5);
  EXPECT_LT(mapped.mismatch_mm, 1e-5);
}

TEST(OpenSimMappingTest, ChildTurnedByAKnownHipMotionGivesAllThreeAngles) {
  BodyMaps maps = identity_like_maps();
  const opensim::Joint* hip = gait2392().find_joint("hip_r");
  ASSERT_NE(hip, nullptr);
  const opensim::CoordinateValues q = {
      {"hip_flexion_r", 0.5}, {"hip_adduction_r", -0.15}, {"hip_rotation_r", 0.25}};
  // The femur's frame must become parent * M(q): turn it, about the hip
  // centre, by P Rp M(q) Rp^T P^T (the default child frame equals the parent
  // frame: all hip coordinates default to 0, and the hip has no translation).
  const Eigen::Isometry3d parent_ground = hip_parent_in_ground(maps, *hip);
  const Eigen::Matrix3d frame = axis_permutation() * parent_ground.linear();
  const Eigen::Matrix3d turn = frame * opensim::joint_motion(*hip, q).linear() * frame.transpose();
  maps.map["femur_r"] = turned_about(base_map(), turn, base_map() * parent_ground.translation());

  const MappedJoint mapped = map_joint(*hip, maps);
  for (const auto& [name, value] : q) {
    EXPECT_NEAR(coordinate_rest(mapped.joint, name), value, 1e-7) << name;  // as above
  }
  EXPECT_LT(mapped.mismatch_deg, 1e-5);
}

TEST(OpenSimMappingTest, AnisotropicMapsGiveProperFramesAndUniformScale) {
  BodyMaps maps = identity_like_maps();
  // Stretch the femur by 10 % along the atlas z (its length) only.
  Eigen::Affine3d stretched = base_map();
  stretched.linear() = Eigen::Vector3d(1.0, 1.0, 1.1).asDiagonal() * stretched.linear();
  maps.map["femur_r"] = stretched;
  EXPECT_NEAR(maps.scale("femur_r"), 1000.0 * std::cbrt(1.1), 1e-9);
  const Eigen::Isometry3d frame = maps.frame("femur_r", Eigen::Isometry3d::Identity());
  // The frame keeps the permutation (the nearest rotation of a stretch along
  // an axis of the permuted frame) and maps the origin as a point.
  EXPECT_LT((frame.linear() - axis_permutation()).norm(), 1e-12);
  EXPECT_LT((frame.translation() - stretched.translation()).norm(), 1e-12);
  const Eigen::Vector3d local(0.01, -0.2, 0.03);
  EXPECT_LT((maps.point("femur_r", local) - stretched * (maps.pose.at("femur_r") * local)).norm(),
            1e-9);
}

TEST(OpenSimMappingTest, UnmappedBodyThrows) {
  BodyMaps maps = identity_like_maps();
  maps.map.erase("femur_r");
  const opensim::Joint* hip = gait2392().find_joint("hip_r");
  ASSERT_NE(hip, nullptr);
  EXPECT_THROW((void)map_joint(*hip, maps), InvalidInputError);
  EXPECT_THROW((void)maps.scale("femur_r"), InvalidInputError);
  EXPECT_FALSE(maps.has("femur_r"));
  EXPECT_TRUE(maps.has("pelvis"));
}

}  // namespace
}  // namespace mmm::atlas

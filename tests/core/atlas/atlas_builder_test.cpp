#include "core/atlas/atlas_builder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "core/atlas/kinematic_chain.h"
#include "core/errors.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::atlas {
namespace {

using Eigen::Vector3d;
using ::testing::ElementsAre;

// A pelvis made of separate bones, as the default atlas has it: the right
// hip bone ("pelvis", the root), the left hip bone and the sacrum welded to
// it, and a femur on a ball joint. x toward the subject's right, mm.
struct SplitPelvis {
  Atlas atlas;
  std::map<std::string, mesh::IndexedMesh> surfaces;
};

SplitPelvis split_pelvis() {
  SplitPelvis p;
  const auto add = [&](const std::string& name, const Vector3d& centre, const Vector3d& radii) {
    Bone bone;
    bone.name = name;
    bone.frame.translation() = centre;
    p.atlas.bones.push_back(bone);
    p.surfaces[name] = test::ellipsoid(centre, radii, 3);
  };
  add("pelvis", Vector3d(90, 0, 0), Vector3d(60, 40, 80));
  add("pelvis_l", Vector3d(-90, 0, 0), Vector3d(60, 40, 80));
  add("sacrum", Vector3d(0, -60, 10), Vector3d(25, 20, 50));
  add("femur_r", Vector3d(100, 0, -250), Vector3d(20, 20, 200));
  const auto join = [&](const std::string& name, const std::string& child, JointType type,
                        const Vector3d& centre) {
    Joint joint;
    joint.name = name;
    joint.type = type;
    joint.parent = "pelvis";
    joint.child = child;
    joint.parent_frame.translation() = centre;
    joint.child_frame.translation() = centre;
    p.atlas.joints.push_back(joint);
    for (Bone& bone : p.atlas.bones) {
      if (bone.name == child) bone.parent_joint = name;
    }
  };
  join("pelvis_l_weld", "pelvis_l", JointType::kWeld, Vector3d::Zero());
  join("sacrum_weld", "sacrum", JointType::kWeld, Vector3d::Zero());
  join("hip_r", "femur_r", JointType::kBall, Vector3d(100, 0, -40));
  return p;
}

TEST(WeldedTogether, FindsTheWholeSegmentFromAnyOfItsBones) {
  const SplitPelvis p = split_pelvis();
  EXPECT_THAT(welded_together(p.atlas, "pelvis"), ElementsAre("pelvis", "pelvis_l", "sacrum"));
  EXPECT_THAT(welded_together(p.atlas, "sacrum"), ElementsAre("pelvis", "pelvis_l", "sacrum"));
  EXPECT_THAT(welded_together(p.atlas, "femur_r"), ElementsAre("femur_r"));
  // The toy leg's patella is welded to its tibia.
  const test::ToyLeg leg = test::toy_leg();
  EXPECT_THAT(welded_together(leg.atlas, "patella_r"), ElementsAre("tibia_r", "patella_r"));
}

// A left-side marker of the pelvis (the left ASIS) lands on the left hip
// bone, not on the nearest part of the right one 100+ mm away: a left ASIS
// landmark on the right pubis tilted the scaled pelvis and threw the
// static-trial marker fit 70 mm off.
TEST(ClosestOnSegment, FindsTheWeldedBoneNearestToTheMarker) {
  const SplitPelvis p = split_pelvis();
  const Vector3d left_asis_marker(-100, 60, 40);
  const BonePoint on = closest_on_segment(p.atlas, p.surfaces, "pelvis", left_asis_marker);
  EXPECT_EQ(on.bone, "pelvis_l");
  EXPECT_LT(on.distance_mm, 30.0);
  EXPECT_LT(on.position.x(), 0.0);  // on the left of the midline
  EXPECT_NEAR((on.position - left_asis_marker).norm(), on.distance_mm, 1e-9);

  const Vector3d right_asis_marker(100, 60, 40);
  const BonePoint right = closest_on_segment(p.atlas, p.surfaces, "pelvis", right_asis_marker);
  EXPECT_EQ(right.bone, "pelvis");
  EXPECT_LT(right.distance_mm, 30.0);
}

TEST(ClosestOnSegment, StaysOnTheSegmentAcrossMovingJoints) {
  const SplitPelvis p = split_pelvis();
  // Beside the femur's shaft: the femur is nearer but moves on its own.
  const BonePoint on = closest_on_segment(p.atlas, p.surfaces, "pelvis", Vector3d(150, 0, -250));
  EXPECT_NE(on.bone, "femur_r");
  const BonePoint femur =
      closest_on_segment(p.atlas, p.surfaces, "femur_r", Vector3d(150, 0, -250));
  EXPECT_EQ(femur.bone, "femur_r");
  EXPECT_NEAR(femur.distance_mm, 30.0, 1.0);
}

TEST(ClosestOnSegment, ThrowsWhenTheSegmentHasNoSurface) {
  const SplitPelvis p = split_pelvis();
  std::map<std::string, mesh::IndexedMesh> femur_only;
  femur_only["femur_r"] = p.surfaces.at("femur_r");
  EXPECT_THROW((void)closest_on_segment(p.atlas, femur_only, "pelvis", Vector3d::Zero()),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::atlas

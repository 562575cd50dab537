// The anatomy checks of `mmm atlas check` on a knee made of boxes whose gaps
// are known: a femur, a tibia 1 mm below it and a patella 2 mm in front of
// it (welded to the tibia, as in gait2392; the tibia narrower than the femur), then the same knee
// with the patella moved away and with the tibia pushed into the femur.

#include "core/atlas/anatomy_check.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/mesh/primitives.h"

namespace mmm::atlas {
namespace {

using ::testing::HasSubstr;

struct BoxKnee {
  Atlas atlas;
  std::map<std::string, mesh::IndexedMesh> bones;

  BoxKnee() {
    const auto bone = [&](const std::string& name, std::vector<std::string> tags,
                          const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
      Bone b;
      b.name = name;
      b.tags = std::move(tags);
      atlas.bones.push_back(b);
      bones[name] = mesh::make_box(low, high);
    };
    bone("femur_r", {"bone", "femur"}, {-20, -20, 0}, {20, 20, 100});
    bone("tibia_r", {"bone", "tibia"}, {-15, -15, -101}, {15, 15, -1});
    bone("patella_r", {"bone", "patella"}, {-10, 22, 10}, {10, 32, 40});
    Joint knee;
    knee.name = "knee_r";
    knee.type = JointType::kPin;
    knee.parent = "femur_r";
    knee.child = "tibia_r";
    Joint weld;
    weld.name = "patella_weld";
    weld.type = JointType::kWeld;
    weld.parent = "tibia_r";
    weld.child = "patella_r";
    atlas.joints = {knee, weld};
    atlas.bones[1].parent_joint = "knee_r";
    atlas.bones[2].parent_joint = "patella_weld";
  }

  void move(const std::string& name, const Eigen::Vector3d& by) {
    bones[name].V.rowwise() += by.transpose();
  }
};

const Articulation& articulation(const AnatomyReport& report, const std::string& name) {
  for (const Articulation& a : report.articulations) {
    if (a.name == name) return a;
  }
  throw std::runtime_error("no articulation " + name);
}

TEST(AnatomyCheckTest, AKneeThatFitsPassesWithItsGapsMeasured) {
  const BoxKnee knee;
  std::vector<std::string> problems;
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, {}, problems);
  EXPECT_TRUE(problems.empty()) << problems.front();
  const Articulation& tibiofemoral = articulation(report, "knee_r");
  EXPECT_EQ(tibiofemoral.a, "femur_r");
  EXPECT_EQ(tibiofemoral.b, "tibia_r");
  EXPECT_NEAR(tibiofemoral.gap_mm, 1.0, 1e-9);
  EXPECT_NEAR(articulation(report, "patellofemoral_r").gap_mm, 2.0, 1e-9);
  EXPECT_NEAR(report.nearest_neighbour_gap_mm.at("patella_r"), 2.0, 1e-9);
  EXPECT_LT(report.hip_centre_offset_mm, 0);  // no hip landmarks here
}

TEST(AnatomyCheckTest, ADisplacedPatellaFailsNamingItAndTheGap) {
  BoxKnee knee;
  knee.move("patella_r", {0, 15, 0});  // 17 mm in front of the femur
  std::vector<std::string> problems;
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, {}, problems);
  EXPECT_NEAR(articulation(report, "patellofemoral_r").gap_mm, 17.0, 1e-9);
  ASSERT_EQ(problems.size(), 2U);
  EXPECT_THAT(problems[0], HasSubstr("bone patella_r is 17.00 mm from its nearest neighbour"));
  EXPECT_THAT(problems[1], HasSubstr("articulation patellofemoral_r: patella_r and femur_r are "
                                     "17.00 mm apart (at most 8.00 mm allowed)"));
}

TEST(AnatomyCheckTest, ABonePushedIntoItsNeighbourFailsWithTheDepth) {
  BoxKnee knee;
  knee.move("tibia_r", {0, 0, 4});  // its top 3 mm inside the femur
  std::vector<std::string> problems;
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, {}, problems);
  EXPECT_NEAR(articulation(report, "knee_r").overlap_mm, 3.0, 1e-9);
  ASSERT_EQ(problems.size(), 1U);
  EXPECT_THAT(problems[0], HasSubstr("enters"));
  EXPECT_THAT(problems[0], HasSubstr("by 3.00 mm (at most 1.00 mm allowed)"));
}

TEST(AnatomyCheckTest, AFemoralHeadOutOfItsSocketFails) {
  BoxKnee knee;
  Landmark head;
  head.name = "femoral_head_centre_r";
  head.bone = "femur_r";
  head.position = {0, 0, 90};
  Landmark socket = head;
  socket.name = "acetabulum_centre_r";
  socket.position = {0, 4, 90};
  knee.atlas.landmarks = {head, socket};
  std::vector<std::string> problems;
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, {}, problems);
  EXPECT_NEAR(report.hip_centre_offset_mm, 4.0, 1e-12);
  ASSERT_EQ(problems.size(), 1U);
  EXPECT_THAT(problems[0], HasSubstr("femoral head is 4.00 mm from the centre of the acetabulum"));
}

}  // namespace
}  // namespace mmm::atlas

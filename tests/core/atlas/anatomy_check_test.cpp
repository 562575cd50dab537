// The anatomy checks of `mmm atlas check` on a knee made of boxes whose gaps
// are known: a femur, a tibia 1 mm below it and a patella 2 mm in front of
// it (welded to the tibia, as in gait2392; the tibia narrower than the femur), then the same knee
// with the patella moved away and with the tibia pushed into the femur. The
// same knee with cartilages (thin boxes on the bones' facing sides, 1 mm
// apart) and a ligament from femur to tibia: a patella displaced by less
// than the bone checks notice is caught by its cartilage.

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
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, {}, {}, problems);
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
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, {}, {}, problems);
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
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, {}, {}, problems);
  EXPECT_NEAR(articulation(report, "knee_r").overlap_mm, 3.0, 1e-9);
  ASSERT_EQ(problems.size(), 1U);
  EXPECT_THAT(problems[0], HasSubstr("enters"));
  EXPECT_THAT(problems[0], HasSubstr("by 3.00 mm (at most 1.00 mm allowed)"));
}

// The box knee with cartilages (6 mm thick where they face across the knee):
// distal femur (its underside and its front, the trochlea), tibial plateau
// 1 mm below, the patella (moved up, clear of the plateau) 1 mm in front of
// the trochlea; and a ligament on the femur's and the tibia's sides.
struct CartilageKnee : BoxKnee {
  std::map<std::string, mesh::IndexedMesh> structures;

  CartilageKnee() {
    bones["patella_r"] = mesh::make_box({-10, 22, 30}, {10, 32, 60});  // above the plateau
    const auto structure = [&](const std::string& name, StructureKind kind,
                               std::vector<std::string> on, const Eigen::Vector3d& low,
                               const Eigen::Vector3d& high) {
      Structure s;
      s.name = name;
      s.kind = kind;
      s.bones = std::move(on);
      atlas.structures.push_back(s);
      structures[name] = mesh::make_box(low, high);
    };
    structure("femur_cartilage_r", StructureKind::kCartilage, {"femur_r"}, {-18, -18, 0},
              {18, 18, 6});
    structure("trochlea_cartilage_r", StructureKind::kCartilage, {"femur_r"}, {-10, 19, 30},
              {10, 20, 60});
    structure("tibia_cartilage_r", StructureKind::kCartilage, {"tibia_r"}, {-14, -14, -7},
              {14, 14, -1});
    structure("patella_cartilage_r", StructureKind::kCartilage, {"patella_r"}, {-8, 21, 32},
              {8, 22, 58});
    structure("collateral_r", StructureKind::kLigament, {"femur_r", "tibia_r"}, {15, -3, -20},
              {17, 3, 20});
  }

  // A bone and the cartilages on it.
  void move_with_cartilage(const std::string& bone, const Eigen::Vector3d& by) {
    move(bone, by);
    for (const Structure& s : atlas.structures) {
      if (s.kind == StructureKind::kCartilage && s.bones.front() == bone) {
        structures[s.name].V.rowwise() += by.transpose();
      }
    }
  }
};

const CartilageContact& cartilage_contact(const AnatomyReport& report, const std::string& a,
                                          const std::string& b) {
  for (const CartilageContact& c : report.cartilage_contacts) {
    if ((c.a == a && c.b == b) || (c.a == b && c.b == a)) return c;
  }
  throw std::runtime_error("no cartilage contact " + a + " - " + b);
}

TEST(AnatomyCheckTest, FacingCartilagesAreMeasuredAcrossEachArticulation) {
  const CartilageKnee knee;
  std::vector<std::string> problems;
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, knee.structures, {}, problems);
  EXPECT_TRUE(problems.empty()) << problems.front();
  const CartilageContact& tibiofemoral =
      cartilage_contact(report, "femur_cartilage_r", "tibia_cartilage_r");
  EXPECT_EQ(tibiofemoral.articulation, "knee_r");
  EXPECT_NEAR(tibiofemoral.gap_mm, 1.0, 1e-9);
  const CartilageContact& patellofemoral =
      cartilage_contact(report, "patella_cartilage_r", "trochlea_cartilage_r");
  EXPECT_EQ(patellofemoral.articulation, "patellofemoral_r");
  EXPECT_NEAR(patellofemoral.gap_mm, 1.0, 1e-9);
  // The plateau does not face the trochlea: no pair for it.
  EXPECT_THROW(
      static_cast<void>(cartilage_contact(report, "trochlea_cartilage_r", "tibia_cartilage_r")),
      std::runtime_error);
  ASSERT_EQ(report.structure_attachments.size(), 6U);  // 4 cartilages, the ligament twice
  for (const StructureAttachment& a : report.structure_attachments) {
    EXPECT_LE(a.gap_mm, 1e-9) << a.structure << " on " << a.bone;
  }
}

TEST(AnatomyCheckTest, APatellaDisplacedLessThanTheBoneChecksSeeFailsByItsCartilage) {
  CartilageKnee knee;
  knee.move_with_cartilage("patella_r", {0, 2.5, 0});  // bones 4.5 mm apart: within 8 mm
  std::vector<std::string> problems;
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, knee.structures, {}, problems);
  EXPECT_NEAR(articulation(report, "patellofemoral_r").gap_mm, 4.5, 1e-9);
  ASSERT_EQ(problems.size(), 1U);
  EXPECT_THAT(problems[0], HasSubstr("articulation patellofemoral_r: cartilages "
                                     "patella_cartilage_r and trochlea_cartilage_r are 3.50 mm "
                                     "apart (at most 3.00 mm allowed)"));
}

TEST(AnatomyCheckTest, CartilagesPushedIntoEachOtherAndOnesThatNoLongerFaceFail) {
  CartilageKnee pushed;
  pushed.move_with_cartilage("tibia_r", {0, 0, 3});  // plateau 2 mm into the femur's
  std::vector<std::string> problems;
  const AnatomyReport report =
      check_anatomy(pushed.atlas, pushed.bones, pushed.structures, {}, problems);
  EXPECT_NEAR(cartilage_contact(report, "femur_cartilage_r", "tibia_cartilage_r").overlap_mm, 2.0,
              1e-9);
  EXPECT_THAT(problems, testing::Contains(HasSubstr("overlap by 2.00 mm (at most 1.50 mm")));

  CartilageKnee away;
  away.move_with_cartilage("patella_r", {0, 15, 0});
  problems.clear();
  check_anatomy(away.atlas, away.bones, away.structures, {}, problems);
  EXPECT_THAT(problems, testing::Contains(HasSubstr(
                            "articulation patellofemoral_r: no cartilage of patella_cartilage_r's "
                            "side faces one of the other side")));
}

TEST(AnatomyCheckTest, ALigamentOffItsBoneFailsNamingTheBone) {
  CartilageKnee knee;
  knee.structures["collateral_r"].V.rowwise() += Eigen::RowVector3d(10, 0, 0);
  std::vector<std::string> problems;
  check_anatomy(knee.atlas, knee.bones, knee.structures, {}, problems);
  ASSERT_EQ(problems.size(), 2U);  // off the femur and off the tibia
  EXPECT_THAT(problems[0],
              HasSubstr("ligament collateral_r is 5.00 mm from its bone femur_r (at most 3.00 mm"));
  EXPECT_THAT(problems[1], HasSubstr("from its bone tibia_r"));
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
  const AnatomyReport report = check_anatomy(knee.atlas, knee.bones, {}, {}, problems);
  EXPECT_NEAR(report.hip_centre_offset_mm, 4.0, 1e-12);
  ASSERT_EQ(problems.size(), 1U);
  EXPECT_THAT(problems[0], HasSubstr("femoral head is 4.00 mm from the centre of the acetabulum"));
}

}  // namespace
}  // namespace mmm::atlas

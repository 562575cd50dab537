// The action line of a muscle without an OpenSim path, on shapes whose answer
// is known: a spindle between two blocks.

#include "core/atlas/surface_line.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "core/mesh/winding_number.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::atlas {
namespace {

// A spindle along z from 20 to 120 mm; the origin block touches its lower
// tip, the insertion block starts 30 mm above its upper tip (a tendon the
// segmentation left out).
struct SpindleBetweenBlocks {
  mesh::IndexedMesh muscle = test::ellipsoid({0, 0, 70}, {10, 10, 50}, 4);
  mesh::IndexedMesh lower = mesh::make_box({-30, -30, -20}, {30, 30, 20});
  mesh::IndexedMesh upper = mesh::make_box({-30, -30, 150}, {30, 30, 180});
  mesh::AabbTree lower_tree{lower};
  mesh::AabbTree upper_tree{upper};
};

TEST(SurfaceLineTest, RunsFromContactToContactThroughTheBellyAndMeasuresTheTendon) {
  const SpindleBetweenBlocks shapes;
  const SurfaceLine line = surface_action_line(
      "spindle", shapes.muscle, {"lower", &shapes.lower_tree}, {"upper", &shapes.upper_tree}, 3.0);
  ASSERT_GE(line.line.points.size(), 5U);  // ends and at least 3 slices
  const PathPoint& origin = line.line.points.front();
  const PathPoint& insertion = line.line.points.back();
  EXPECT_EQ(origin.bone, "lower");
  EXPECT_EQ(insertion.bone, "upper");
  EXPECT_NEAR(origin.position.z(), 20.0, 1e-6);  // on the block's face
  EXPECT_NEAR(origin.position.head<2>().norm(), 0.0, 0.5);
  EXPECT_NEAR(insertion.position.z(), 150.0, 1e-6);
  EXPECT_NEAR(insertion.position.head<2>().norm(), 0.0, 2.0);
  const mesh::AabbTree tree(shapes.muscle);
  const mesh::WindingNumber winding(tree);
  for (std::size_t i = 1; i + 1 < line.line.points.size(); ++i) {
    EXPECT_TRUE(winding.is_inside(line.line.points[i].position)) << line.line.points[i].name;
    EXPECT_EQ(line.line.points[i].bone, line.line.points[i].position.z() < 85 ? "lower" : "upper");
  }
  // The via points either side of the change of bone, ~9 mm apart, would
  // pass through each other as the joint moves: they only follow the line.
  int followers = 0;
  for (std::size_t i = 1; i + 1 < line.line.points.size(); ++i) {
    const PathPoint& point = line.line.points[i];
    const bool straddles =
        point.bone != line.line.points[i - 1].bone || point.bone != line.line.points[i + 1].bone;
    EXPECT_EQ(point.kind == PathPointKind::kFollowsLine, straddles) << point.name;
    followers += point.kind == PathPointKind::kFollowsLine ? 1 : 0;
  }
  EXPECT_EQ(followers, 2);
  // Belly 100 mm (the spindle), tendon the 30 mm gap (0.5 mm sampling).
  EXPECT_NEAR(line.belly_mm, 100.0, 1.5);
  EXPECT_NEAR(line.tendon_mm, 30.0, 1.5);
}

TEST(SurfaceLineTest, EndsThatFallTogetherAreRefused) {
  const SpindleBetweenBlocks shapes;
  EXPECT_THROW(
      static_cast<void>(surface_action_line("spindle", shapes.muscle, {"lower", &shapes.lower_tree},
                                            {"lower", &shapes.lower_tree}, 3.0)),
      InvalidInputError);
}

}  // namespace
}  // namespace mmm::atlas

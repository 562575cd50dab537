#include "core/atlas/action_line_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/primitives.h"
#include "core/mesh/winding_number.h"

namespace mmm::atlas {
namespace {

constexpr double kTubeRadius = 10.0;  // mm
constexpr int kSegments = 32;         // vertices around a ring

// Points move however far their contact or section centre lies: the fit's
// geometry alone, without the limits that keep a model's points in place.
ActionLineFitOptions without_shift_limits() {
  ActionLineFitOptions options;
  options.max_end_shift_mm = std::numeric_limits<double>::infinity();
  options.max_via_shift_mm = std::numeric_limits<double>::infinity();
  return options;
}

// The straight tube muscle with one action line, "tube_line", through `points`.
Muscle tube_muscle(std::vector<PathPoint> points) {
  Muscle muscle;
  muscle.name = "tube";
  ActionLine line;
  line.name = "tube_line";
  line.points = std::move(points);
  muscle.action_lines = {line};
  return muscle;
}

// A closed tube of radius r swept along a centre line: rings of kSegments
// vertices around centres[k] in the plane spanned by u[k], v[k] (unit,
// perpendicular to the line), closed by a fan around each end's centre.
// Oriented outward (flipped as a whole if it came out inward).
mesh::IndexedMesh swept_tube(const std::vector<Eigen::Vector3d>& centres,
                             const std::vector<Eigen::Vector3d>& u,
                             const std::vector<Eigen::Vector3d>& v, double radius) {
  const int rings = static_cast<int>(centres.size());
  mesh::IndexedMesh tube;
  tube.V.resize(static_cast<Eigen::Index>(rings) * kSegments + 2, 3);
  for (int k = 0; k < rings; ++k) {
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * std::numbers::pi * j / kSegments;
      tube.V.row(k * kSegments + j) =
          (centres[k] + radius * (std::cos(phi) * u[k] + std::sin(phi) * v[k])).transpose();
    }
  }
  const int first = rings * kSegments;
  const int last = first + 1;
  tube.V.row(first) = centres.front().transpose();
  tube.V.row(last) = centres.back().transpose();
  tube.F.resize(2 * static_cast<Eigen::Index>(rings - 1) * kSegments +
                    2 * static_cast<Eigen::Index>(kSegments),
                3);
  Eigen::Index f = 0;
  for (int k = 0; k + 1 < rings; ++k) {
    for (int j = 0; j < kSegments; ++j) {
      const int a = k * kSegments + j;
      const int b = k * kSegments + (j + 1) % kSegments;
      tube.F.row(f++) << a, b, b + kSegments;
      tube.F.row(f++) << a, b + kSegments, a + kSegments;
    }
  }
  for (int j = 0; j < kSegments; ++j) {
    const int next = (j + 1) % kSegments;
    tube.F.row(f++) << first, next, j;
    tube.F.row(f++) << last, (rings - 1) * kSegments + j, (rings - 1) * kSegments + next;
  }
  if (mesh::signed_volume(tube) < 0) tube.F.col(1).swap(tube.F.col(2));
  return tube;
}

// Straight tube along z from z = 0 to z = 100, rings every 2 mm.
mesh::IndexedMesh straight_tube() {
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Vector3d> u;
  std::vector<Eigen::Vector3d> v;
  for (int k = 0; k <= 50; ++k) {
    centres.emplace_back(0, 0, 2.0 * k);
    u.emplace_back(Eigen::Vector3d::UnitX());
    v.emplace_back(Eigen::Vector3d::UnitY());
  }
  return swept_tube(centres, u, v, kTubeRadius);
}

// A C-shaped (arched) tube: its centre line is the upper half of the circle
// of radius 50 mm around the origin in the xz plane, from (50, 0, 0) over
// (0, 0, 50) to (-50, 0, 0); both ends face down (-z). Rings every ~2 mm.
constexpr double kArchRadius = 50.0;
mesh::IndexedMesh arch_tube() {
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Vector3d> u;
  std::vector<Eigen::Vector3d> v;
  const int rings = 79;
  for (int k = 0; k < rings; ++k) {
    const double a = std::numbers::pi * k / (rings - 1);
    centres.emplace_back(kArchRadius * std::cos(a), 0, kArchRadius * std::sin(a));
    u.emplace_back(std::cos(a), 0, std::sin(a));
    v.emplace_back(Eigen::Vector3d::UnitY());
  }
  return swept_tube(centres, u, v, kTubeRadius);
}

PathPoint point(const std::string& name, const std::string& bone, const Eigen::Vector3d& at,
                PathPointKind kind = PathPointKind::kFixed) {
  PathPoint p;
  p.name = name;
  p.bone = bone;
  p.position = at;
  p.kind = kind;
  return p;
}

// A muscle surface with its inside test and the bones the lines name.
struct Scene {
  mesh::IndexedMesh surface;
  mesh::AabbTree tree;
  mesh::WindingNumber winding;
  std::function<bool(const Eigen::Vector3d&)> inside;
  std::vector<std::unique_ptr<mesh::AabbTree>> bone_trees;
  std::map<std::string, const mesh::AabbTree*> bones;

  explicit Scene(const mesh::IndexedMesh& muscle)
      : surface(muscle),
        tree(muscle),
        winding(tree),
        inside([this](const Eigen::Vector3d& p) { return winding.is_inside(p); }) {}
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  void add_bone(const std::string& name, const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
    bone_trees.push_back(std::make_unique<mesh::AabbTree>(mesh::make_box(low, high)));
    bones[name] = bone_trees.back().get();
  }
};

// The straight tube standing between two bone boxes that touch its end caps.
std::unique_ptr<Scene> straight_scene() {
  auto scene = std::make_unique<Scene>(straight_tube());
  scene->add_bone("top", Eigen::Vector3d(-30, -30, 100), Eigen::Vector3d(30, 30, 130));
  scene->add_bone("bottom", Eigen::Vector3d(-30, -30, -30), Eigen::Vector3d(30, 30, 0));
  return scene;
}

TEST(ActionLineFitTest, TubeSurfaceIsAClosedSolid) {
  // The generated muscles themselves: closed, outward (a precondition of the
  // inside test every other test relies on).
  for (const mesh::IndexedMesh& tube : {straight_tube(), arch_tube()}) {
    EXPECT_TRUE(mesh::check_mesh(tube).watertight());
    EXPECT_GT(mesh::signed_volume(tube), 0.0);
  }
}

TEST(ActionLineFitTest, LineBesideAStraightMuscleMovesInsideAndOntoTheContacts) {
  const auto scene = straight_scene();
  // 12 mm off the axis: entirely outside the 10 mm tube.
  Muscle muscle =
      tube_muscle({point("origin", "top", {12, 0, 103}), point("via", "bottom", {12, 0, 50}),
                   point("insertion", "bottom", {12, 0, -3})});

  const auto reports =
      fit_action_lines(muscle, scene->tree, scene->inside, scene->bones, without_shift_limits());
  ASSERT_EQ(reports.size(), 1U);
  const ActionLineFitReport& report = reports.front();
  EXPECT_EQ(report.line, "tube_line");
  EXPECT_EQ(report.inside_before, 0.0);
  EXPECT_GT(report.inside_after, report.inside_before);
  EXPECT_GE(report.inside_after, 0.9);
  EXPECT_TRUE(report.origin_on_contact);
  EXPECT_TRUE(report.insertion_on_contact);

  const ActionLine& fitted = muscle.action_lines.front();
  ASSERT_GE(fitted.points.size(), 3U);
  // The contact vertices (the cap and the rings within 3 mm of the bone) are
  // symmetric about the axis, so their centroid's nearest bone point is the
  // cap centre, up to rounding.
  EXPECT_LT((fitted.points.front().position - Eigen::Vector3d(0, 0, 100)).norm(), 1e-6);
  EXPECT_LT((fitted.points.back().position - Eigen::Vector3d(0, 0, 0)).norm(), 1e-6);
  EXPECT_EQ(fitted.points.front().bone, "top");
  EXPECT_EQ(fitted.points.back().bone, "bottom");
  // The via point goes to its section's centre: on the axis (the tube's
  // deepest points; the rings are symmetric), within a ring spacing of z=50.
  const Eigen::Vector3d via = fitted.points[1].position;
  EXPECT_LT(via.head<2>().norm(), 1e-6);
  EXPECT_NEAR(via.z(), 50.0, 2.0);
  // The axis lies inside, so no segment needed a split.
  EXPECT_EQ(report.points_added, 0);
  EXPECT_EQ(fitted.points.size(), 3U);
}

TEST(ActionLineFitTest, AnEndFarFromTheContactStaysWhereTheModelPutsIt) {
  // The belly ends short of a long tendon: its contact with the bone, 40 mm
  // from the model's origin, is not where the tendon attaches.
  const auto scene = straight_scene();
  const Muscle original =
      tube_muscle({point("origin", "top", {40, 0, 100}), point("insertion", "bottom", {5, 0, -3})});
  Muscle muscle = original;
  const auto reports = fit_action_lines(muscle, scene->tree, scene->inside, scene->bones);
  EXPECT_FALSE(reports.front().origin_on_contact);
  EXPECT_TRUE(reports.front().insertion_on_contact);
  EXPECT_EQ(muscle.action_lines.front().points.front().position, Eigen::Vector3d(40, 0, 100));
  // Allowed a longer shift, it moves onto the contact.
  muscle = original;
  ActionLineFitOptions far;
  far.max_end_shift_mm = 45;
  const auto moved = fit_action_lines(muscle, scene->tree, scene->inside, scene->bones, far);
  EXPECT_TRUE(moved.front().origin_on_contact);
  EXPECT_LT(
      (muscle.action_lines.front().points.front().position - Eigen::Vector3d(0, 0, 100)).norm(),
      1e-6);
}

TEST(ActionLineFitTest, AViaPointFarFromItsSectionCentreStaysAndTheDrawnPathBendsInside) {
  // The model's via point runs 25 mm off the tube's axis (a tendon over the
  // bone, beside a thick belly): beyond the 15 mm limit it keeps its place,
  // and the points added to keep the path inside only follow the line.
  const auto scene = straight_scene();
  const Muscle original =
      tube_muscle({point("origin", "top", {0, 0, 103}), point("via", "bottom", {25, 0, 50}),
                   point("insertion", "bottom", {0, 0, -3})});
  Muscle muscle = original;
  const auto reports = fit_action_lines(muscle, scene->tree, scene->inside, scene->bones);
  const ActionLine& kept = muscle.action_lines.front();
  const auto via =
      std::ranges::find_if(kept.points, [](const PathPoint& p) { return p.name == "via"; });
  ASSERT_NE(via, kept.points.end());
  EXPECT_EQ(via->position, Eigen::Vector3d(25, 0, 50));
  EXPECT_GT(reports.front().points_added, 0);
  for (const PathPoint& p : kept.points) {
    if (p.kind == PathPointKind::kFollowsLine) {
      EXPECT_TRUE(scene->inside(p.position)) << p.name;
    }
  }
  // Allowed a longer shift, it moves onto the section's centre, on the axis.
  muscle = original;
  ActionLineFitOptions far;
  far.max_via_shift_mm = 30;
  fit_action_lines(muscle, scene->tree, scene->inside, scene->bones, far);
  const PathPoint& moved = muscle.action_lines.front().points[1];
  EXPECT_EQ(moved.name, "via");
  EXPECT_LT(moved.position.head<2>().norm(), 1e-6);
  EXPECT_NEAR(moved.position.z(), 50.0, 2.0);
}

TEST(ActionLineFitTest, NoEndLandsOnAnArticularSurface) {
  // The top bone's face is articular on its x < 0 half: the contacts there
  // do not count, and the origin moves onto the other half.
  const auto scene = straight_scene();
  Muscle muscle =
      tube_muscle({point("origin", "top", {0, 0, 103}), point("insertion", "bottom", {0, 0, -3})});
  ActionLineFitOptions options;
  options.articular = [](const Eigen::Vector3d& p) { return p.z() >= 99.0 && p.x() < 0.0; };
  const auto reports = fit_action_lines(muscle, scene->tree, scene->inside, scene->bones, options);
  EXPECT_TRUE(reports.front().origin_on_contact);
  const PathPoint& origin = muscle.action_lines.front().points.front();
  EXPECT_GT(origin.position.x(), 2.0);
  EXPECT_FALSE(options.articular(origin.position));
  EXPECT_NEAR(muscle.action_lines.front().points.back().position.x(), 0.0, 1e-6);
}

TEST(ActionLineFitTest, ArchedMuscleGetsViaPointsAlongItsCurve) {
  Scene scene(arch_tube());
  // Each end of the arch stands on its own bone box.
  scene.add_bone("right_foot", Eigen::Vector3d(30, -20, -20), Eigen::Vector3d(70, 20, 0));
  scene.add_bone("left_foot", Eigen::Vector3d(-70, -20, -20), Eigen::Vector3d(-30, 20, 0));
  Muscle muscle;
  muscle.name = "arch";
  ActionLine line;
  line.name = "arch_line";
  // The generic line cuts across the arch's opening: outside the muscle but
  // for its ends.
  line.points = {point("origin", "right_foot", {60, 0, -5}), point("via", "right_foot", {0, 0, 20}),
                 point("insertion", "left_foot", {-60, 0, -5})};
  muscle.action_lines = {line};

  const auto reports =
      fit_action_lines(muscle, scene.tree, scene.inside, scene.bones, without_shift_limits());
  ASSERT_EQ(reports.size(), 1U);
  const ActionLineFitReport& report = reports.front();
  EXPECT_LT(report.inside_before, 0.2);
  EXPECT_GT(report.inside_after, report.inside_before);
  EXPECT_GE(report.inside_after, 0.9);
  EXPECT_GT(report.points_added, 0);
  EXPECT_TRUE(report.origin_on_contact);
  EXPECT_TRUE(report.insertion_on_contact);

  const ActionLine& fitted = muscle.action_lines.front();
  EXPECT_EQ(fitted.points.size(), 3U + static_cast<std::size_t>(report.points_added));
  // Ends onto the cap centres on the bones' top faces: the contact vertices'
  // centroid leans ~1 mm towards the arch's inner side, well within 1 mm
  // along the face.
  EXPECT_LT((fitted.points.front().position - Eigen::Vector3d(50, 0, 0)).norm(), 1.0);
  EXPECT_LT((fitted.points.back().position - Eigen::Vector3d(-50, 0, 0)).norm(), 1.0);
  // Every point between lies within the tube, near its centre line (the
  // section centres are the deepest points among candidates, spread at most
  // a few mm off the axis in a 10 mm tube).
  for (std::size_t i = 1; i + 1 < fitted.points.size(); ++i) {
    const Eigen::Vector3d p = fitted.points[i].position;
    EXPECT_NEAR(std::hypot(p.x(), p.z()), kArchRadius, 0.5 * kTubeRadius) << i;
    EXPECT_TRUE(scene.inside(p)) << i;
    EXPECT_TRUE(fitted.points[i].bone == "right_foot" || fitted.points[i].bone == "left_foot");
  }
  // Added points are named after the line and attached to the nearer bone.
  int added = 0;
  for (const PathPoint& p : fitted.points) {
    if (p.name.starts_with("arch_line-fit")) {
      ++added;
      EXPECT_EQ(p.bone, p.position.x() >= 0 ? "right_foot" : "left_foot") << p.name;
    }
  }
  EXPECT_EQ(added, report.points_added);
}

TEST(ActionLineFitTest, SplitPointsRideOnTheNearestBoneAlongTheChain) {
  // The arch spans two bones through a third one at its apex (as a
  // hamstring spans pelvis -> femur -> tibia): points near the apex belong
  // to the middle bone, not to either end's.
  Scene scene(arch_tube());
  scene.add_bone("right_foot", Eigen::Vector3d(30, -20, -20), Eigen::Vector3d(70, 20, 0));
  scene.add_bone("left_foot", Eigen::Vector3d(-70, -20, -20), Eigen::Vector3d(-30, 20, 0));
  const double top = kArchRadius + kTubeRadius + 2.0;
  scene.add_bone("keystone", Eigen::Vector3d(-15, -20, top), Eigen::Vector3d(15, 20, top + 10));
  Muscle muscle;
  muscle.name = "arch";
  ActionLine line;
  line.name = "arch_line";
  line.points = {point("origin", "right_foot", {60, 0, -5}), point("via", "right_foot", {0, 0, 20}),
                 point("insertion", "left_foot", {-60, 0, -5})};
  muscle.action_lines = {line};
  ActionLineFitOptions options = without_shift_limits();
  options.parent_bone = {{"right_foot", "keystone"}, {"left_foot", "keystone"}};
  const auto reports = fit_action_lines(muscle, scene.tree, scene.inside, scene.bones, options);
  ASSERT_GT(reports.front().points_added, 0);
  int on_keystone = 0;
  for (const PathPoint& p : muscle.action_lines.front().points) {
    if (!p.name.starts_with("arch_line-fit")) continue;
    // Each on the nearest of the three.
    std::string nearest;
    double best = std::numeric_limits<double>::infinity();
    for (const char* bone : {"right_foot", "left_foot", "keystone"}) {
      const double d = scene.bones.at(bone)->closest_point(p.position).squared_distance;
      if (d < best) {
        best = d;
        nearest = bone;
      }
    }
    EXPECT_EQ(p.bone, nearest) << p.name;
    on_keystone += p.bone == "keystone" ? 1 : 0;
  }
  EXPECT_GT(on_keystone, 0);

  // With the joints' centres, a point belongs to the bone past whose joint
  // it lies along the segment: right of x = 20 the right foot, left of
  // x = -20 the left one, the keystone between.
  muscle.action_lines = {line};
  options.joint_centre = {{"right_foot", Eigen::Vector3d(20, 0, 60)},
                          {"left_foot", Eigen::Vector3d(-20, 0, 60)}};
  fit_action_lines(muscle, scene.tree, scene.inside, scene.bones, options);
  for (const PathPoint& p : muscle.action_lines.front().points) {
    if (!p.name.starts_with("arch_line-fit")) continue;
    const double x = p.position.x();
    EXPECT_EQ(p.bone, x > 20 ? "right_foot" : (x < -20 ? "left_foot" : "keystone")) << p.name;
  }
}

TEST(ActionLineFitTest, MovingPointsStay) {
  const auto scene = straight_scene();
  Muscle muscle = tube_muscle({point("origin", "top", {18, 0, 103}, PathPointKind::kMoving),
                               point("via", "bottom", {0, 0, 50}, PathPointKind::kMoving),
                               point("insertion", "bottom", {0, 0, -3})});
  const auto reports = fit_action_lines(muscle, scene->tree, scene->inside, scene->bones);
  ASSERT_EQ(reports.size(), 1U);
  EXPECT_FALSE(reports.front().origin_on_contact);
  EXPECT_TRUE(reports.front().insertion_on_contact);
  // The moving points keep their places (they may get fitted neighbours:
  // the segments between them and the muscle are split).
  const ActionLine& fitted = muscle.action_lines.front();
  EXPECT_EQ(fitted.points.front().position, Eigen::Vector3d(18, 0, 103));
  const auto via = std::ranges::find(fitted.points, std::string("via"), &PathPoint::name);
  ASSERT_NE(via, fitted.points.end());
  EXPECT_EQ(via->position, Eigen::Vector3d(0, 0, 50));
  EXPECT_EQ(via->kind, PathPointKind::kMoving);
}

TEST(ActionLineFitTest, TwoLinesShareTheMuscleIntoBundles) {
  // Two lines on either side of the axis: each fits into its own half, the
  // vertices nearest it, so they stay apart (a line taking the whole muscle
  // would end on the axis).
  const auto scene = straight_scene();
  Muscle muscle;
  muscle.name = "tube";
  ActionLine left;
  left.name = "left";
  left.points = {point("o", "top", {-6, 0, 101}), point("i", "bottom", {-6, 0, -1})};
  ActionLine right;
  right.name = "right";
  right.points = {point("o", "top", {6, 0, 101}), point("i", "bottom", {6, 0, -1})};
  muscle.action_lines = {left, right};
  const auto reports = fit_action_lines(muscle, scene->tree, scene->inside, scene->bones);
  ASSERT_EQ(reports.size(), 2U);
  const ActionLine& l = muscle.action_lines[0];
  const ActionLine& r = muscle.action_lines[1];
  // Each end on its bone face, on its own side of the axis.
  EXPECT_NEAR(l.points.front().position.z(), 100.0, 1e-9);
  EXPECT_NEAR(r.points.back().position.z(), 0.0, 1e-9);
  EXPECT_LT(l.points.front().position.x(), -1.0);
  EXPECT_GT(r.points.front().position.x(), 1.0);
  EXPECT_LT(l.points.back().position.x(), -1.0);
  EXPECT_GT(r.points.back().position.x(), 1.0);
  for (const ActionLineFitReport& report : reports) EXPECT_GE(report.inside_after, 0.9);
}

TEST(ActionLineFitTest, UnknownBoneThrows) {
  const auto scene = straight_scene();
  Muscle muscle = tube_muscle(
      {point("origin", "skull", {0, 0, 101}), point("insertion", "bottom", {0, 0, -1})});
  EXPECT_THROW((void)fit_action_lines(muscle, scene->tree, scene->inside, scene->bones),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::atlas

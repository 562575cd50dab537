// The muscle-muscle penetration metric on two spheres: their overlap at rest
// is measured and not counted, a sphere moved deeper is measured by how much
// deeper, and a wrapped trial gets the metric filled per muscle-frame. The
// contacts between muscles on the same spheres: shared contacts meet on the
// plane between them, shares grow over rounds, pins keep the latest, new
// entries are found with or without the clearance shortcut alike.

#include "core/wrapping/muscle_penetration.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "core/wrapping/muscle_wrapping.h"

namespace mmm::wrapping {
namespace {

constexpr double kPenetrationSphereRadius = 10.0;

mesh::IndexedMesh penetration_sphere_at(const Eigen::Vector3d& centre) {
  mesh::IndexedMesh sphere = mesh::make_icosphere(3, kPenetrationSphereRadius);
  sphere.V.rowwise() += centre.transpose();
  return sphere;
}

MuscleSurfaces surfaces_of(const mesh::IndexedMesh& a, const mesh::IndexedMesh& b) {
  return MuscleSurfaces({a.V, b.V}, {&a.F, &b.F}, 2);
}

TEST(MusclePenetrationTest, TheRestOverlapIsMeasuredAndNotCounted) {
  // Two spheres 15 mm apart overlap by 5 mm.
  const mesh::IndexedMesh a = penetration_sphere_at({0, 0, 0});
  const mesh::IndexedMesh b = penetration_sphere_at({15, 0, 0});
  const MuscleSurfaces rest = surfaces_of(a, b);
  const RestOverlap overlap = rest_overlap(0, a.V, rest);
  ASSERT_EQ(overlap.size(), 1U);
  ASSERT_EQ(overlap.count(1), 1U);
  // A's vertex at (10, 0, 0) is the deepest, 5 mm inside B (to the mesh's resolution).
  Eigen::Index tip = 0;
  a.V.col(0).maxCoeff(&tip);
  EXPECT_NEAR(overlap.at(1)[tip], 5.0, 0.1);
  EXPECT_EQ(overlap.at(1).maxCoeff(), overlap.at(1)[tip]);
  const MusclePenetration measured = measure_muscle_penetration(0, a.V, rest, overlap, 0.1);
  EXPECT_NEAR(measured.max_depth_mm, 0.0, 1e-12);
  EXPECT_EQ(measured.vertices_deeper, 0);
  EXPECT_EQ(measured.deepest_muscle, -1);
  // Without the rest overlap the same surfaces count 5 mm.
  EXPECT_NEAR(measure_muscle_penetration(0, a.V, rest, {}, 0.1).max_depth_mm, 5.0, 0.1);
}

TEST(MusclePenetrationTest, AMuscleMovedDeeperIsMeasuredByHowMuchDeeper) {
  const mesh::IndexedMesh a = penetration_sphere_at({0, 0, 0});
  const mesh::IndexedMesh b = penetration_sphere_at({15, 0, 0});
  const RestOverlap overlap = rest_overlap(0, a.V, surfaces_of(a, b));
  mesh::IndexedMesh moved = a;
  moved.V.col(0).array() += 2.0;  // A moves 2 mm into B
  const MuscleSurfaces now = surfaces_of(moved, b);
  const MusclePenetration measured = measure_muscle_penetration(0, moved.V, now, overlap, 0.1);
  EXPECT_NEAR(measured.max_depth_mm, 2.0, 0.2);
  EXPECT_EQ(measured.deepest_muscle, 1);
  EXPECT_GT(measured.vertices_deeper, 0);
  // A vertex that was outside B at rest and is inside now counts fully:
  // nothing of A's far side is near B, so B sees A's near side only.
  const MusclePenetration of_b =
      measure_muscle_penetration(1, b.V, now, rest_overlap(1, b.V, surfaces_of(a, b)), 0.1);
  EXPECT_NEAR(of_b.max_depth_mm, 2.0, 0.2);
}

TEST(MusclePenetrationTest, AWrappedTrialGetsTheMetricPerMuscleFrame) {
  MuscleWrapping wrapped;
  wrapped.times = Eigen::VectorXd::LinSpaced(2, 0.0, 0.01);
  for (const Eigen::Vector3d& centre : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(15, 0, 0)}) {
    WrappedMuscle muscle;
    muscle.rest = penetration_sphere_at(centre);
    // Frame 0: as at rest, moved rigidly by 100 mm (depths do not change);
    // frame 1: the first sphere 3 mm further into the second.
    Eigen::MatrixX3d frame = muscle.rest.V;
    frame.col(2).array() += 100.0;
    muscle.positions.emplace_back(frame.cast<float>());
    if (centre.x() == 0.0) frame.col(0).array() += 3.0;
    muscle.positions.emplace_back(frame.cast<float>());
    muscle.frames.resize(2);
    wrapped.muscles.push_back(std::move(muscle));
  }
  measure_muscle_penetration(wrapped, 0.1, 2);
  EXPECT_LT(wrapped.muscles[0].frames[0].muscle_depth_mm, 1e-4);  // float positions
  EXPECT_EQ(wrapped.muscles[0].frames[0].muscle_vertices_deeper, 0);
  EXPECT_NEAR(wrapped.muscles[0].frames[1].muscle_depth_mm, 3.0, 0.2);
  EXPECT_EQ(wrapped.muscles[0].frames[1].deepest_muscle, 1);
  EXPECT_NEAR(wrapped.muscles[1].frames[1].muscle_depth_mm, 3.0, 0.2);
  EXPECT_EQ(wrapped.muscles[1].frames[1].deepest_muscle, 0);
}

TEST(MusclePenetrationTest, MismatchedInputIsAnError) {
  const mesh::IndexedMesh a = penetration_sphere_at({0, 0, 0});
  EXPECT_THROW(MuscleSurfaces({a.V, a.V}, {&a.F}, 1), InvalidInputError);
  const MuscleSurfaces two = surfaces_of(a, penetration_sphere_at({15, 0, 0}));
  EXPECT_THROW((void)shared_muscle_contacts({a.V}, two, {}, 1), InvalidInputError);
  MuscleContactOptions bad;
  bad.share = 1.5;
  EXPECT_THROW((void)shared_muscle_contacts({a.V, a.V}, two, bad, 1), InvalidInputError);
  MusclePins pins(2);
  EXPECT_THROW((void)pins.add({{}}), InvalidInputError);
}

TEST(MuscleContactsTest, TwoOverlappingMusclesAreToMeetOnThePlaneBetweenThem) {
  // Spheres at x = 0 and x = 15 (radius 10) overlap between x = 5 and 10;
  // with equal shares both are to end on the plane x = 7.5.
  const mesh::IndexedMesh a = penetration_sphere_at({0, 0, 0});
  const mesh::IndexedMesh b = penetration_sphere_at({15, 0, 0});
  const MuscleSurfaces now = surfaces_of(a, b);
  const std::vector<std::vector<Contact>> contacts = shared_muscle_contacts({a.V, b.V}, now, {}, 2);
  ASSERT_EQ(contacts.size(), 2U);
  ASSERT_FALSE(contacts[0].empty());
  ASSERT_FALSE(contacts[1].empty());
  // The icosphere's facets against the true sphere; off the axis, moves go
  // along the other sphere's facet normals, not exactly along x.
  const double resolution = 0.3;
  const double off_axis = 0.5;
  for (const Contact& contact : contacts[0]) {
    EXPECT_LT(contact.target.x(), 7.5 + off_axis) << "vertex " << contact.vertex;
    EXPECT_GT(contact.target.x(), a.V(contact.vertex, 0) - 2.5 - resolution);
    EXPECT_EQ(contact.obstacle, muscle_obstacle(1));
    EXPECT_TRUE(is_muscle_obstacle(contact.obstacle));
    EXPECT_EQ(contact.weight, MuscleContactOptions{}.weight);
  }
  for (const Contact& contact : contacts[1]) {
    EXPECT_GT(contact.target.x(), 7.5 - off_axis) << "vertex " << contact.vertex;
    EXPECT_EQ(contact.obstacle, muscle_obstacle(0));
  }
  // A's tip (10, 0, 0) and B's (5, 0, 0) both go to the middle.
  Eigen::Index a_tip = 0;
  Eigen::Index b_tip = 0;
  a.V.col(0).maxCoeff(&a_tip);
  b.V.col(0).minCoeff(&b_tip);
  const auto target_of = [](const std::vector<Contact>& list, Eigen::Index vertex) {
    for (const Contact& contact : list) {
      if (contact.vertex == vertex) return contact.target;
    }
    return Eigen::Vector3d(Eigen::Vector3d::Constant(std::nan("")));
  };
  EXPECT_NEAR(target_of(contacts[0], a_tip).x(), 7.5, resolution);
  EXPECT_NEAR(target_of(contacts[1], b_tip).x(), 7.5, resolution);
  // All of it to the penetrating side: A's tip to B's surface, B's stays.
  MuscleContactOptions all;
  all.share = 1.0;
  const std::vector<std::vector<Contact>> one_sided =
      shared_muscle_contacts({a.V, b.V}, now, all, 1);
  EXPECT_NEAR(target_of(one_sided[0], a_tip).x(), 5.0, resolution);
  // Apart, nothing.
  const mesh::IndexedMesh far = penetration_sphere_at({25, 0, 0});
  const std::vector<std::vector<Contact>> apart =
      shared_muscle_contacts({a.V, far.V}, surfaces_of(a, far), {}, 1);
  EXPECT_TRUE(apart[0].empty());
  EXPECT_TRUE(apart[1].empty());
}

TEST(MuscleContactsTest, TheLongestMoveIsTheDeepestEntryWhenTheEnteringSideTakesItAll) {
  // Sphere A's tip (x near 10) lies about 2 mm inside the block B (x >= 8);
  // with all of the overlap to A, B's corners stay and A's tip moves out to
  // the block's face x = 8.
  const mesh::IndexedMesh a = penetration_sphere_at({0, 0, 0});
  const mesh::IndexedMesh b = mesh::make_box({8.0, -20.0, -20.0}, {28.0, 20.0, 20.0});
  const MuscleSurfaces now = surfaces_of(a, b);
  MuscleContactOptions all;
  all.share = 1.0;
  const std::vector<std::vector<Contact>> found = shared_muscle_contacts({a.V, b.V}, now, all, 1);
  ASSERT_FALSE(found[0].empty());
  EXPECT_NEAR(longest_move(found, {a.V, b.V}), a.V.col(0).maxCoeff() - 8.0, 1e-9);
  EXPECT_GT(longest_move(found, {a.V, b.V}), 1.5);
  EXPECT_DOUBLE_EQ(longest_move({{}, {}}, {a.V, b.V}), 0.0);
  EXPECT_THROW((void)longest_move(found, {a.V}), InvalidInputError);
  std::vector<std::vector<Contact>> bad = found;
  bad[0][0].vertex = static_cast<int>(a.V.rows());
  EXPECT_THROW((void)longest_move(bad, {a.V, b.V}), InvalidInputError);
}

TEST(MuscleContactsTest, SharesGrowToAllOfTheOverlapInTheLastRound) {
  EXPECT_DOUBLE_EQ(round_share(0.5, 0, 1), 0.5);
  EXPECT_DOUBLE_EQ(round_share(0.5, 0, 2), 0.5);
  EXPECT_DOUBLE_EQ(round_share(0.5, 1, 2), 1.0);
  EXPECT_DOUBLE_EQ(round_share(0.5, 1, 3), 0.75);
  EXPECT_DOUBLE_EQ(round_share(0.3, 0, 3), 0.7);  // never less than half
  EXPECT_DOUBLE_EQ(round_share(0.5, 7, 3), 1.0);  // past the last: all
}

TEST(MuscleContactsTest, PinsKeepEachVertexsLatestContact) {
  MusclePins pins(2);
  EXPECT_FALSE(pins.add({{}, {}}));
  EXPECT_TRUE(pins.empty(0));
  EXPECT_TRUE(pins.add({{Contact{3, Eigen::Vector3d(1, 0, 0), -3}}, {}}));
  EXPECT_TRUE(pins.add(
      {{Contact{3, Eigen::Vector3d(2, 0, 0), -3}, Contact{5, Eigen::Vector3d::Zero(), -3}}, {}}));
  const std::vector<Contact> of_a = pins.of(0);
  ASSERT_EQ(of_a.size(), 2U);
  EXPECT_EQ(of_a[0].vertex, 3);
  EXPECT_EQ(of_a[0].target.x(), 2.0);
  EXPECT_TRUE(pins.empty(1));
}

TEST(MuscleContactsTest, NewEntriesAreTheSameWithTheClearanceShortcut) {
  const mesh::IndexedMesh a = penetration_sphere_at({0, 0, 0});
  // 2.6 mm apart, their boxes overlapping.
  const Eigen::Vector3d b_centre(16, 16, 0);
  const mesh::IndexedMesh b = penetration_sphere_at(b_centre);
  const MuscleSurfaces found_on = surfaces_of(a, b);
  std::vector<MuscleClearance> clearances;
  const std::vector<std::vector<Contact>> none =
      shared_muscle_contacts({a.V, b.V}, found_on, {}, 1, &clearances);
  EXPECT_TRUE(none[0].empty());
  ASSERT_EQ(clearances.size(), 2U);
  ASSERT_EQ(clearances[0].clearance.count(1), 1U);
  // A lower bound of each vertex's distance to B (the box's, away from B).
  const Eigen::VectorXd& clearance = clearances[0].clearance.at(1);
  EXPECT_GT(clearance.minCoeff(), 0.0);
  for (Eigen::Index v = 0; v < a.V.rows(); ++v) {
    const double distance = (a.V.row(v).transpose() - b_centre).norm() - kPenetrationSphereRadius;
    EXPECT_LE(clearance[v], distance + 0.1) << "vertex " << v;  // facets within 0.1 mm
  }
  // A's half facing B then grows by 40 % (a solve could do this): its front enters B.
  Eigen::MatrixX3d grown = a.V;
  for (Eigen::Index v = 0; v < grown.rows(); ++v) {
    if (grown(v, 0) + grown(v, 1) > 0) grown.row(v) *= 1.4;
  }
  const std::vector<char> none_active(static_cast<std::size_t>(a.V.rows()), 0);
  const MuscleContactOptions options;
  const std::vector<Contact> full = muscle_entries(0, grown, none_active, found_on, options);
  const std::vector<Contact> pruned =
      muscle_entries(0, grown, none_active, found_on, options, &clearances.front());
  ASSERT_FALSE(full.empty());
  ASSERT_EQ(full.size(), pruned.size());
  for (std::size_t i = 0; i < full.size(); ++i) {
    EXPECT_EQ(full[i].vertex, pruned[i].vertex);
    EXPECT_EQ(full[i].target, pruned[i].target);
    // Pinned onto B's surface: 10 mm from its centre.
    EXPECT_NEAR((full[i].target - b_centre).norm(), kPenetrationSphereRadius, 0.05);
  }
  // Active vertices are left alone.
  std::vector<char> active = none_active;
  active[static_cast<std::size_t>(full.front().vertex)] = 1;
  EXPECT_EQ(muscle_entries(0, grown, active, found_on, options).size(), full.size() - 1);
}

}  // namespace
}  // namespace mmm::wrapping

// The muscle-muscle penetration metric on two spheres: their overlap at rest
// is measured and not counted, a sphere moved deeper is measured by how much
// deeper, and a wrapped trial gets the metric filled per muscle-frame.

#include "core/wrapping/muscle_penetration.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "core/wrapping/muscle_wrapping.h"

namespace mmm::wrapping {
namespace {

constexpr double kRadius = 10.0;

mesh::IndexedMesh sphere_at(const Eigen::Vector3d& centre) {
  mesh::IndexedMesh sphere = mesh::make_icosphere(3, kRadius);
  sphere.V.rowwise() += centre.transpose();
  return sphere;
}

MuscleSurfaces surfaces_of(const mesh::IndexedMesh& a, const mesh::IndexedMesh& b) {
  return MuscleSurfaces({a.V, b.V}, {&a.F, &b.F}, 2);
}

TEST(MusclePenetrationTest, TheRestOverlapIsMeasuredAndNotCounted) {
  // Two spheres 15 mm apart overlap by 5 mm.
  const mesh::IndexedMesh a = sphere_at({0, 0, 0});
  const mesh::IndexedMesh b = sphere_at({15, 0, 0});
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
  const mesh::IndexedMesh a = sphere_at({0, 0, 0});
  const mesh::IndexedMesh b = sphere_at({15, 0, 0});
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
    muscle.rest = sphere_at(centre);
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
  const mesh::IndexedMesh a = sphere_at({0, 0, 0});
  EXPECT_THROW(MuscleSurfaces({a.V, a.V}, {&a.F}, 1), InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping

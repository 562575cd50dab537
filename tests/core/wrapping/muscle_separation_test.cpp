// Separating muscles that overlap at rest: two overlapping spheres end apart
// with their volumes, a muscle that overlaps nothing is left exactly as it
// is, and a muscle pressed against a bone lets the other take the overlap.

#include "core/wrapping/muscle_separation.h"

#include <gtest/gtest.h>

#include <memory>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::wrapping {
namespace {

mesh::IndexedMesh separation_sphere_at(const Eigen::Vector3d& centre, double radius = 10.0) {
  mesh::IndexedMesh sphere = mesh::make_icosphere(3, radius);
  sphere.V.rowwise() += centre.transpose();
  return sphere;
}

double deepest(const MuscleSeparation& separation, const std::vector<mesh::IndexedMesh>& surfaces) {
  std::vector<const Eigen::MatrixX3i*> faces;
  faces.reserve(surfaces.size());
  for (const mesh::IndexedMesh& surface : surfaces) faces.push_back(&surface.F);
  const MuscleSurfaces now(separation.positions, faces, 1);
  double depth = 0.0;
  for (std::size_t m = 0; m < surfaces.size(); ++m) {
    depth = std::max(depth, measure_muscle_penetration(static_cast<int>(m), separation.positions[m],
                                                       now, {}, 0.0)
                                .max_depth_mm);
  }
  return depth;
}

TEST(MuscleSeparationTest, TwoOverlappingSpheresEndApartWithTheirVolumes) {
  // 3 mm of overlap between the first two; the third is far from both.
  const std::vector<mesh::IndexedMesh> surfaces = {separation_sphere_at({0, 0, 0}),
                                                   separation_sphere_at({17, 0, 0}),
                                                   separation_sphere_at({0, 60, 0})};
  const MuscleSeparation separation = separate_muscles(surfaces, {}, {}, 2);
  ASSERT_EQ(separation.positions.size(), 3U);
  EXPECT_NEAR(separation.overlap_before_mm[0], 3.0, 0.2);
  EXPECT_NEAR(separation.overlap_before_mm[1], 3.0, 0.2);
  EXPECT_LT(separation.overlap_after_mm[0], 0.3);
  EXPECT_LT(separation.overlap_after_mm[1], 0.3);
  EXPECT_LT(deepest(separation, surfaces), 0.3);
  EXPECT_GE(separation.rounds, 1);
  for (std::size_t m = 0; m < 2; ++m) {
    EXPECT_LT(std::abs(separation.volume_error_percent[m]), 1e-6) << m;
    // Each gives way by about half of the overlap, not all of it.
    EXPECT_GT(separation.max_move_mm[m], 0.8) << m;
    EXPECT_LT(separation.max_move_mm[m], 3.0) << m;
  }
  // The first moves back from the second (-x) and the second away (+x).
  EXPECT_LT(separation.positions[0].col(0).maxCoeff(), surfaces[0].V.col(0).maxCoeff() - 0.8);
  EXPECT_GT(separation.positions[1].col(0).minCoeff(), surfaces[1].V.col(0).minCoeff() + 0.8);
  EXPECT_EQ(separation.max_move_mm[2], 0.0);
  EXPECT_EQ(separation.positions[2], surfaces[2].V);
}

TEST(MuscleSeparationTest, AMusclePressedOnABoneLetsTheOtherTakeTheOverlap) {
  // The second sphere sits on a bone (a big sphere behind it): it cannot give
  // way, so the first takes the overlap, and the second stays out of the bone.
  const std::vector<mesh::IndexedMesh> surfaces = {separation_sphere_at({0, 0, 0}),
                                                   separation_sphere_at({17, 0, 0})};
  const mesh::IndexedMesh bone_mesh = separation_sphere_at({57.05, 0, 0}, 30.0);
  const std::vector<PosableBone> bones = {
      {"bone", std::make_shared<const mesh::SignedDistance>(bone_mesh)}};
  const MuscleSeparation separation = separate_muscles(surfaces, bones, {}, 2);
  EXPECT_LT(deepest(separation, surfaces), 0.3);
  const mesh::SignedDistance& bone = *bones.front().surface;
  double into_bone = 0.0;
  for (Eigen::Index v = 0; v < separation.positions[1].rows(); ++v)
    into_bone = std::max(into_bone, -bone.at(Eigen::Vector3d(separation.positions[1].row(v))));
  EXPECT_LT(into_bone, ContactOptions{}.tolerance_mm + 0.05);
  EXPECT_LT(std::abs(separation.volume_error_percent[0]), 1e-6);
  EXPECT_LT(std::abs(separation.volume_error_percent[1]), 1e-6);
}

TEST(MuscleSeparationTest, BadOptionsAreRefused) {
  SeparationOptions options;
  options.max_rounds = 0;
  EXPECT_THROW((void)separate_muscles({separation_sphere_at({0, 0, 0})}, {}, options, 1),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping

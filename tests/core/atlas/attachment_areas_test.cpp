#include "core/atlas/attachment_areas.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "core/mesh/aabb_tree.h"
#include "core/mesh/primitives.h"

namespace mmm::atlas {
namespace {

// Bone: a sphere of radius 20 mm at the origin, 5 subdivisions (faces
// ~0.7 mm across). Muscles: spheres of radius 10 mm.
constexpr double kBoneRadius = 20.0;
constexpr double kMuscleRadius = 10.0;
// An area is a set of whole faces, taken when their centroid qualifies, so
// its rim is off the exact curve by up to a face: the area is off by at most
// the rim's length times the largest face diameter (0.75 mm here).
constexpr double kFaceSize = 0.75;

double face_area(const mesh::IndexedMesh& surface, int f) {
  const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)).transpose();
  const Eigen::Vector3d b = surface.V.row(surface.F(f, 1)).transpose();
  const Eigen::Vector3d c = surface.V.row(surface.F(f, 2)).transpose();
  return 0.5 * (b - a).cross(c - a).norm();
}

Eigen::Vector3d face_centroid(const mesh::IndexedMesh& surface, int f) {
  return (surface.V.row(surface.F(f, 0)) + surface.V.row(surface.F(f, 1)) +
          surface.V.row(surface.F(f, 2)))
             .transpose() /
         3.0;
}

class AttachmentAreaTest : public ::testing::Test {
 protected:
  mesh::AabbTree bone{mesh::make_icosphere(5, kBoneRadius)};
  // Touching the bone at (20, 0, 0).
  mesh::AabbTree touching{mesh::make_icosphere(4, kMuscleRadius, Eigen::Vector3d(30, 0, 0))};
  // Touching the bone at (0, 20, 0).
  mesh::AabbTree above{mesh::make_icosphere(4, kMuscleRadius, Eigen::Vector3d(0, 30, 0))};
  // 10 mm clear of the bone.
  mesh::AabbTree apart{mesh::make_icosphere(4, kMuscleRadius, Eigen::Vector3d(40, 0, 0))};
};

TEST_F(AttachmentAreaTest, TouchingSpheresGiveACapAroundTheContact) {
  bool fell_back = true;
  const AttachmentArea area =
      find_attachment_area("ball", bone, touching, Eigen::Vector3d(22, 0, 0), {}, &fell_back);
  EXPECT_FALSE(fell_back);
  EXPECT_EQ(area.bone, "ball");
  ASSERT_FALSE(area.faces.empty());
  // Bone points within 3 mm of the muscle sphere: |p - (30,0,0)| <= 13, the
  // cap of half-angle phi with cos(phi) = (20^2 + 30^2 - 13^2) / (2 20 30).
  const double cos_phi = (400.0 + 900.0 - 169.0) / 1200.0;
  const double cap_area = 2 * std::numbers::pi * kBoneRadius * kBoneRadius * (1 - cos_phi);
  const double rim = 2 * std::numbers::pi * kBoneRadius * std::sqrt(1 - cos_phi * cos_phi);
  EXPECT_NEAR(area.area_mm2, cap_area, rim * kFaceSize);  // 144.5 +- 31 mm^2
  // The cap's area centroid is on the axis at 20 (1 + cos phi) / 2 = 19.4 mm;
  // the faceting breaks the symmetry by a fraction of a face.
  EXPECT_LT((area.centroid - Eigen::Vector3d(kBoneRadius * (1 + cos_phi) / 2, 0, 0)).norm(),
            kFaceSize);
  EXPECT_LT((area.centroid - Eigen::Vector3d(20, 0, 0)).norm(), 1.0);  // near the contact
  // Every face of the area qualifies: centroid within 3 mm of the muscle
  // sphere (the faceted spheres lie within 0.01 mm inside the true ones) and
  // within 30 mm of the end.
  double sum = 0.0;
  for (const int f : area.faces) {
    const Eigen::Vector3d c = face_centroid(bone.mesh(), f);
    EXPECT_LE((c - Eigen::Vector3d(30, 0, 0)).norm() - kMuscleRadius, 3.0 + 0.01) << f;
    sum += face_area(bone.mesh(), f);
  }
  EXPECT_NEAR(area.area_mm2, sum, 1e-9 * sum);  // the reported area is its faces'
  // No duplicates.
  EXPECT_EQ(std::set<int>(area.faces.begin(), area.faces.end()).size(), area.faces.size());
}

TEST_F(AttachmentAreaTest, RadiusLimitsTheAreaAroundTheEnd) {
  AttachmentOptions options;
  options.radius_mm = 5.0;
  const Eigen::Vector3d end(20, 0, 0);
  const AttachmentArea area = find_attachment_area("ball", bone, touching, end, options);
  for (const int f : area.faces) {
    EXPECT_LE((face_centroid(bone.mesh(), f) - end).norm(), 5.0) << f;
  }
  // The 5 mm ball around the contact lies inside the 6.8 mm (chord) contact
  // cap: the area is the cap of chord 5 mm, whose area is pi 5^2 exactly on a
  // sphere, within the rim's faces.
  EXPECT_NEAR(area.area_mm2, std::numbers::pi * 25.0, 2 * std::numbers::pi * 5.0 * kFaceSize);
}

TEST_F(AttachmentAreaTest, MuscleClearOfTheBoneFallsBackToAPatchUnderTheEnd) {
  bool fell_back = false;
  const AttachmentArea area =
      find_attachment_area("ball", bone, apart, Eigen::Vector3d(25, 0, 0), {}, &fell_back);
  EXPECT_TRUE(fell_back);
  ASSERT_FALSE(area.faces.empty());
  // Faces within 8 mm (fallback_radius_mm) of the bone point closest to the
  // end, (20, 0, 0): a cap of chord 8 mm, of area pi 8^2.
  EXPECT_NEAR(area.area_mm2, std::numbers::pi * 64.0, 2 * std::numbers::pi * 8.0 * kFaceSize);
  EXPECT_LT((area.centroid - Eigen::Vector3d(20, 0, 0)).norm(), 2.0);  // the cap sags 1.6 mm
  EXPECT_LT(std::abs(area.centroid.y()) + std::abs(area.centroid.z()), kFaceSize);

  // A fallback radius smaller than any face still gives the face under the end.
  AttachmentOptions tiny;
  tiny.fallback_radius_mm = 1e-3;
  const AttachmentArea single =
      find_attachment_area("ball", bone, apart, Eigen::Vector3d(25, 0, 0), tiny, &fell_back);
  EXPECT_TRUE(fell_back);
  ASSERT_EQ(single.faces.size(), 1U);
  EXPECT_EQ(single.faces.front(), bone.closest_point(Eigen::Vector3d(25, 0, 0)).face);
  EXPECT_NEAR(single.area_mm2, face_area(bone.mesh(), single.faces.front()), 1e-12);
}

TEST_F(AttachmentAreaTest, EndFarFromTheContactFallsBack) {
  // The muscle touches the bone at (20, 0, 0), but the end sits at the far
  // side (-20, 0, 0): no contact face within 30 mm, so the patch goes there.
  bool fell_back = false;
  const AttachmentArea area =
      find_attachment_area("ball", bone, touching, Eigen::Vector3d(-21, 0, 0), {}, &fell_back);
  EXPECT_TRUE(fell_back);
  EXPECT_LT(area.centroid.x(), -18.0);
}

TEST_F(AttachmentAreaTest, MergeUnitesTheFaces) {
  const AttachmentArea side =
      find_attachment_area("ball", bone, touching, Eigen::Vector3d(20, 0, 0));
  const AttachmentArea top = find_attachment_area("ball", bone, above, Eigen::Vector3d(0, 20, 0));
  ASSERT_FALSE(side.faces.empty());
  ASSERT_FALSE(top.faces.empty());

  // Disjoint areas: every face once, the areas add, the centroid is their
  // area-weighted mean.
  const AttachmentArea both = merge_attachment_areas(side, top, bone.mesh());
  EXPECT_EQ(both.bone, "ball");
  EXPECT_EQ(both.faces.size(), side.faces.size() + top.faces.size());
  EXPECT_TRUE(std::is_sorted(both.faces.begin(), both.faces.end()));
  EXPECT_NEAR(both.area_mm2, side.area_mm2 + top.area_mm2, 1e-9 * both.area_mm2);
  const Eigen::Vector3d mean =
      (side.area_mm2 * side.centroid + top.area_mm2 * top.centroid) / both.area_mm2;
  EXPECT_LT((both.centroid - mean).norm(), 1e-9);  // rounding of mm-sized sums

  // Overlapping areas: the common faces count once.
  AttachmentOptions small;
  small.radius_mm = 4.0;
  const AttachmentArea inner =
      find_attachment_area("ball", bone, touching, Eigen::Vector3d(20, 0, 0), small);
  const AttachmentArea same = merge_attachment_areas(side, inner, bone.mesh());
  std::vector<int> sorted = side.faces;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(same.faces, sorted);
  EXPECT_NEAR(same.area_mm2, side.area_mm2, 1e-9 * side.area_mm2);
  EXPECT_LT((same.centroid - side.centroid).norm(), 1e-9);
}

}  // namespace
}  // namespace mmm::atlas

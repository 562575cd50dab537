#include "core/mesh/penetration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"

namespace mmm::mesh {
namespace {

TEST(PenetrationTest, OverlappingSpheresPenetrateByHalfTheirRadius) {
  const double radius = 10.0;
  const Eigen::Vector3d center_b(15, 0, 0);
  const IndexedMesh a = make_icosphere(4, radius);
  const IndexedMesh b = make_icosphere(4, radius, center_b);
  const PenetrationReport report = penetration(a, b);
  // A's vertex (10, 0, 0) (an edge midpoint of the icosahedron, on the sphere)
  // is 5 mm from B's centre; B's polyhedron lies between radius - gap and
  // radius from that centre, so its depth is in [5 - gap, 5], and no vertex of
  // A (all on a sphere) is deeper than 5.
  const double gap = test::icosphere_gap(b, radius, center_b);
  EXPECT_LT(gap, 0.02);  // subdivision 4: edge ~0.7 mm, gap ~ edge^2 / 60 mm
  EXPECT_GT(report.vertices_inside, 0);
  EXPECT_EQ(report.vertices_inside, static_cast<int>(report.inside_vertices.size()));
  EXPECT_GE(report.max_depth, 5.0 - gap - 1e-12);  // 1e-12: rounding at 10 mm
  EXPECT_LE(report.max_depth, 5.0 + 1e-12);
  ASSERT_GE(report.deepest_vertex, 0);
  EXPECT_LT((a.V.row(report.deepest_vertex) - Eigen::RowVector3d(10, 0, 0)).norm(), 1e-12);
  EXPECT_TRUE(std::is_sorted(report.inside_vertices.begin(), report.inside_vertices.end()));
  // Away from B's gap band, the listed vertices are exactly those inside B's sphere.
  for (int v = 0; v < a.num_vertices(); ++v) {
    const double from_b = (a.V.row(v).transpose() - center_b).norm();
    const bool listed =
        std::binary_search(report.inside_vertices.begin(), report.inside_vertices.end(), v);
    if (from_b < radius - gap) {
      EXPECT_TRUE(listed) << "vertex " << v;
    }
    if (from_b > radius) {
      EXPECT_FALSE(listed) << "vertex " << v;
    }
  }
}

TEST(PenetrationTest, DisjointSpheresDoNotPenetrate) {
  const IndexedMesh a = make_icosphere(3, 10.0);
  const SignedDistance b(make_icosphere(3, 10.0, Eigen::Vector3d(0, 25, 0)));
  const PenetrationReport report = penetration(a, b);
  EXPECT_EQ(report.vertices_inside, 0);
  EXPECT_EQ(report.max_depth, 0.0);
  EXPECT_EQ(report.deepest_vertex, -1);
  EXPECT_TRUE(report.inside_vertices.empty());
}

TEST(PenetrationTest, BoxInsideBoxHasExactDepth) {
  const IndexedMesh inner =
      make_box(Eigen::Vector3d(-0.5, -0.5, -0.5), Eigen::Vector3d(0.5, 0.5, 0.25));
  const SignedDistance outer(make_box(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)));
  const PenetrationReport report = penetration(inner, outer);
  EXPECT_EQ(report.vertices_inside, 8);
  // Every corner of the inner box is 0.5 from the nearest outer face; planar
  // faces, so only rounding remains.
  EXPECT_NEAR(report.max_depth, 0.5, 1e-12);
}

TEST(PenetrationTest, RejectsInvalidVertices) {
  IndexedMesh a = make_icosphere(1, 1.0);
  a.V(3, 1) = std::nan("");
  const SignedDistance b(make_icosphere(1, 1.0));
  EXPECT_THROW((void)penetration(a, b), InvalidInputError);
}

}  // namespace
}  // namespace mmm::mesh

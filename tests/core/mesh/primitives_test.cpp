#include "core/mesh/primitives.h"

#include <gtest/gtest.h>

namespace mmm::mesh {
namespace {

TEST(PrimitivesTest, IcosphereCountsFollowSubdivision) {
  for (int level = 0; level <= 4; ++level) {
    const IndexedMesh sphere = make_icosphere(level);
    const int scale = 1 << (2 * level);
    EXPECT_EQ(sphere.num_faces(), 20 * scale);
    EXPECT_EQ(sphere.num_vertices(), 10 * scale + 2);
    // Every vertex lies on the unit sphere up to rounding.
    EXPECT_NEAR(sphere.V.rowwise().norm().maxCoeff(), 1.0, 1e-12);
    EXPECT_NEAR(sphere.V.rowwise().norm().minCoeff(), 1.0, 1e-12);
  }
}

TEST(PrimitivesTest, HalfEdgeRoundTripKeepsEverything) {
  const IndexedMesh torus = make_torus(3.0, 1.0, 24, 12);
  ConversionReport report;
  const Mesh halfedge = to_halfedge(torus, &report);
  EXPECT_TRUE(report.rejected_faces.empty());
  const IndexedMesh back = to_indexed(halfedge);
  EXPECT_EQ(back.V, torus.V);
  EXPECT_EQ(back.F, torus.F);
}

}  // namespace
}  // namespace mmm::mesh

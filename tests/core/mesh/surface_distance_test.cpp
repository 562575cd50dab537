#include "core/mesh/surface_distance.h"

#include <gtest/gtest.h>

#include "core/mesh/primitives.h"

namespace mmm::mesh {
namespace {

TEST(SurfaceDistanceTest, IdenticalSurfacesAreZeroApart) {
  const IndexedMesh sphere = make_icosphere(3, 20.0);
  const SurfaceDistance d = surface_distance(sphere, sphere);
  EXPECT_NEAR(d.mean_mm, 0.0, 1e-12);
  EXPECT_NEAR(d.max_mm, 0.0, 1e-12);
  EXPECT_EQ(d.samples, 2 * sphere.V.rows());
}

TEST(SurfaceDistanceTest, ConcentricSpheresAreTheirRadiusDifferenceApart) {
  // Vertices lie on the true spheres; the flat faces between them sit
  // inside by at most r (1 - cos(edge angle / 2)): ~0.3 % of r at 4
  // subdivisions, so the distance is 2 mm to within a few hundredths.
  const IndexedMesh inner = make_icosphere(4, 20.0);
  const IndexedMesh outer = make_icosphere(4, 22.0);
  const SurfaceDistance d = surface_distance(inner, outer);
  EXPECT_NEAR(d.mean_mm, 2.0, 0.08);
  EXPECT_NEAR(d.p95_mm, 2.0, 0.08);
  EXPECT_NEAR(d.max_mm, 2.0, 0.08);
}

TEST(SurfaceDistanceTest, AShiftedCopyIsAtMostTheShiftApart) {
  const IndexedMesh box = make_box({0, 0, 0}, {10, 10, 10});
  IndexedMesh moved = box;
  moved.V.col(0).array() += 1.0;
  const SurfaceDistance d = surface_distance(box, moved);
  EXPECT_NEAR(d.max_mm, 1.0, 1e-12);
  EXPECT_GT(d.mean_mm, 0.0);
}

}  // namespace
}  // namespace mmm::mesh

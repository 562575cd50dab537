#include "core/image/silhouette.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::image {
namespace {

using ::testing::HasSubstr;

// The default pair: 0.229 mm pixels at the isocentre (the origin).
RadiographView frontal_view() { return make_biplanar_views()[0]; }

TEST(SilhouetteTest, ASphereHasOneClosedCircularOutline) {
  const RadiographView view = frontal_view();
  const double radius_mm = 40;
  const mesh::IndexedMesh sphere = mesh::make_icosphere(3, radius_mm);
  const std::vector<Polyline2d> polylines = silhouette_polylines(sphere, view);
  ASSERT_EQ(polylines.size(), 1U);
  const Polyline2d& outline = polylines.front();
  ASSERT_GT(outline.size(), 20U);
  EXPECT_EQ(outline.front(), outline.back()) << "a closed loop repeats its first point";
  const Eigen::Vector2d centre = project(view, Eigen::Vector3d::Zero());
  // The silhouette circle of a sphere at the isocentre, in pixels (the
  // perspective widens it by d / sqrt(d^2 - r^2) = 1.0005: negligible).
  const double expected_px = radius_mm / view.pixel_spacing_mm;
  for (const Eigen::Vector2d& p : outline) {
    // A subdivision-3 icosphere's contour zigzags over faces whose edges
    // span ~0.16 rad: its vertices lie within 2% of the true circle.
    EXPECT_NEAR((p - centre).norm(), expected_px, 0.02 * expected_px);
  }
}

TEST(SilhouetteTest, ThePolylinesHoldExactlyTheKeptSilhouetteEdges) {
  const RadiographView view = make_biplanar_views()[1];
  const mesh::IndexedMesh torus = mesh::make_torus(50, 15, 48, 24);
  const std::vector<std::array<int, 2>> kept =
      keep_contour_pieces(silhouette_edges(torus, view.source_mm), 8);
  std::size_t segments = 0;
  for (const Polyline2d& polyline : silhouette_polylines(torus, view)) {
    EXPECT_GE(polyline.size(), 2U);
    segments += polyline.size() - 1;
  }
  EXPECT_EQ(segments, kept.size());
  EXPECT_EQ(silhouette_polylines(torus, view), silhouette_polylines(torus, view))
      << "deterministic";
}

TEST(SilhouetteTest, SmallPiecesAreDroppedButNeverTheLargest) {
  const mesh::IndexedMesh box = mesh::make_box({-10, -10, -10}, {10, 10, 10});
  const RadiographView view = frontal_view();
  const std::vector<std::array<int, 2>> edges = silhouette_edges(box, view.source_mm);
  ASSERT_FALSE(edges.empty());
  // A box's outline has 4 to 6 edges: fewer than 8, kept as the largest piece.
  EXPECT_EQ(keep_contour_pieces(edges, 8), edges);
  EXPECT_EQ(keep_contour_pieces(edges, 1), edges);
  EXPECT_EQ(silhouette_polylines(box, view).size(), 1U);
}

TEST(SilhouetteTest, AnEmptyMeshHasNoOutlineAndBadInputIsNamed) {
  const RadiographView view = frontal_view();
  EXPECT_TRUE(silhouette_polylines(mesh::IndexedMesh{}, view).empty());
  const mesh::IndexedMesh sphere = mesh::make_icosphere(1, 10);
  EXPECT_THROW(silhouette_polylines(sphere, view, 0), InvalidInputError);
  // 100 mm behind the source, on the central ray.
  const Eigen::Vector3d away = view.source_mm.normalized();  // the isocentre is the origin
  const mesh::IndexedMesh behind = mesh::make_icosphere(1, 10, view.source_mm + 100 * away);
  try {
    silhouette_polylines(behind, view);
    FAIL() << "a mesh behind the source was outlined";
  } catch (const InvalidInputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("view 'frontal'"));
    EXPECT_THAT(error.what(), HasSubstr("behind the source plane"));
  }
}

}  // namespace
}  // namespace mmm::image

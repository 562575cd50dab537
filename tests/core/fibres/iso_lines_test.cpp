// Level sets on meshes: a plane section of a sphere is one closed circle,
// oriented counter-clockwise about the direction in which the values grow,
// enclosing the circle's area; a level below every value cuts nothing; an
// open surface gives an open piece.

#include "core/fibres/iso_lines.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::fibres {
namespace {

TEST(IsoLines, PlaneSectionOfASphereIsOneCounterClockwiseCircle) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(5, 10.0);
  const Eigen::VectorXd z = sphere.V.col(2);
  const std::vector<IsoLine> lines = iso_lines(sphere, z, 3.0);
  ASSERT_EQ(lines.size(), 1U);
  ASSERT_TRUE(lines[0].closed);
  const Eigen::MatrixX3d& loop = lines[0].points;
  EXPECT_GT(loop.rows(), 100);
  EXPECT_LT((loop.col(2).array() - 3.0).abs().maxCoeff(), 1e-9);
  // Points on edges of the sphere's polyhedron: radius within the chord sag.
  const Eigen::ArrayXd radius = loop.leftCols(2).rowwise().norm().array();
  const double expected = std::sqrt(100.0 - 9.0);
  EXPECT_LT((radius - expected).abs().maxCoeff(), 0.05);
  const Eigen::Vector3d area = vector_area(loop);
  EXPECT_GT(area.z(), 0.0);  // counter-clockwise about +z, where z grows
  EXPECT_NEAR(area.norm(), std::numbers::pi * expected * expected, 0.01 * 91 * std::numbers::pi);
  EXPECT_NEAR(enclosed_area(loop), area.norm(), 1e-9);
  // The reversed field turns the loop the other way.
  const std::vector<IsoLine> reversed = iso_lines(sphere, -z, -3.0);
  ASSERT_EQ(reversed.size(), 1U);
  EXPECT_LT(vector_area(reversed[0].points).z(), 0.0);
}

TEST(IsoLines, LevelOutsideTheValuesCutsNothing) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(2, 10.0);
  EXPECT_TRUE(iso_lines(sphere, sphere.V.col(2), 11.0).empty());
  EXPECT_EQ(largest_loop(iso_lines(sphere, sphere.V.col(2), 11.0)).rows(), 0);
}

TEST(IsoLines, TwoSpheresGiveTwoLoopsAndTheLargestIsPicked) {
  mesh::IndexedMesh a = mesh::make_icosphere(3, 10.0);
  const mesh::IndexedMesh b = mesh::make_icosphere(3, 5.0);
  mesh::IndexedMesh both;
  both.V.resize(a.V.rows() + b.V.rows(), 3);
  both.V << a.V, (b.V.rowwise() + Eigen::RowVector3d(40, 0, 0));
  both.F.resize(a.F.rows() + b.F.rows(), 3);
  both.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  const std::vector<IsoLine> lines = iso_lines(both, both.V.col(2), 1.0);
  ASSERT_EQ(lines.size(), 2U);
  const Eigen::MatrixX3d largest = largest_loop(lines);
  EXPECT_LT(largest.col(0).maxCoeff(), 10.0);  // the big sphere's circle
}

TEST(IsoLines, OpenSurfaceGivesAnOpenPiece) {
  // A square of two triangles, cut across.
  mesh::IndexedMesh square;
  square.V.resize(4, 3);
  square.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  square.F.resize(2, 3);
  square.F << 0, 1, 2, 0, 2, 3;
  const std::vector<IsoLine> lines = iso_lines(square, square.V.col(0), 0.5);
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_FALSE(lines[0].closed);
  EXPECT_EQ(lines[0].points.rows(), 3);  // bottom edge, diagonal, top edge
}

TEST(IsoLines, BadInputIsRefused) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(1, 1.0);
  EXPECT_THROW((void)iso_lines(sphere, Eigen::VectorXd::Zero(3), 0.0), InvalidInputError);
  Eigen::VectorXd values = sphere.V.col(2);
  values(0) = std::nan("");
  EXPECT_THROW((void)iso_lines(sphere, values, 0.0), InvalidInputError);
  EXPECT_THROW((void)iso_lines(sphere, sphere.V.col(2), std::nan("")), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fibres

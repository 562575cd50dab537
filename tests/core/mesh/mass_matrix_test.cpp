#include "core/mesh/mass_matrix.h"

#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"

namespace mmm::mesh {
namespace {

IndexedMesh single_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  IndexedMesh mesh;
  mesh.V.resize(3, 3);
  mesh.V.row(0) = a.transpose();
  mesh.V.row(1) = b.transpose();
  mesh.V.row(2) = c.transpose();
  mesh.F.resize(1, 3);
  mesh.F << 0, 1, 2;
  return mesh;
}

TEST(MassMatrixTest, IsDiagonal) {
  const IndexedMesh sphere = make_icosphere(2);
  for (const MassType type : {MassType::kBarycentric, MassType::kVoronoi}) {
    const Eigen::SparseMatrix<double> M = mass_matrix(sphere.V, sphere.F, type);
    ASSERT_EQ(M.rows(), sphere.V.rows());
    ASSERT_EQ(M.cols(), sphere.V.rows());
    EXPECT_EQ(M.nonZeros(), sphere.V.rows());
    for (Eigen::Index col = 0; col < M.outerSize(); ++col) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(M, col); it; ++it) {
        EXPECT_EQ(it.row(), it.col());
        EXPECT_GT(it.value(), 0.0);
      }
    }
  }
}

TEST(MassMatrixTest, SumsToSurfaceAreaOfIcosphereAndBox) {
  const IndexedMesh sphere = make_icosphere(3, 7.5);
  const double sphere_area = test::surface_area(sphere);
  // The inscribed polyhedron is a little smaller than the sphere.
  ASSERT_NEAR(sphere_area, 4.0 * std::numbers::pi * 7.5 * 7.5, 0.01 * sphere_area);
  const IndexedMesh box = make_box(Eigen::Vector3d(-1.0, 0.0, 2.0), Eigen::Vector3d(1.0, 3.0, 6.0));
  const double box_area = 2.0 * (2.0 * 3.0 + 3.0 * 4.0 + 4.0 * 2.0);
  for (const MassType type : {MassType::kBarycentric, MassType::kVoronoi}) {
    // Both lumpings only redistribute each triangle's area; the sums differ
    // by rounding over ~1e3 terms.
    EXPECT_NEAR(mass_matrix(sphere.V, sphere.F, type).sum(), sphere_area, 1e-12 * sphere_area);
    EXPECT_NEAR(mass_matrix(box.V, box.F, type).sum(), box_area, 1e-12 * box_area);
  }
}

TEST(MassMatrixTest, BarycentricMassIsAThirdOfTheIncidentArea) {
  const IndexedMesh grid = test::make_jittered_grid(9, 1.5, 0.4, 11U);
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(grid.V.rows());
  for (Eigen::Index f = 0; f < grid.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) expected(grid.F(f, k)) += test::triangle_area(grid, f) / 3.0;
  }
  const Eigen::VectorXd mass = mass_matrix(grid.V, grid.F, MassType::kBarycentric).diagonal();
  // Same sums of the same areas, up to rounding of the area formula.
  EXPECT_LE((mass - expected).cwiseAbs().maxCoeff(), 1e-14 * expected.maxCoeff());
}

TEST(MassMatrixTest, VoronoiCellsOfARightTriangleGridAreSquares) {
  // Without jitter every triangle is right-angled, its circumcentre is the
  // midpoint of the hypotenuse, and the Voronoi cell of an interior vertex is
  // the h by h square around it (h/2 by h on an edge of the grid).
  const double h = 0.8;
  const int n = 7;
  const IndexedMesh grid = test::make_jittered_grid(n, h, 0.0, 3U);
  const Eigen::VectorXd mass = mass_matrix(grid.V, grid.F, MassType::kVoronoi).diagonal();
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      const bool row_inside = r > 0 && r < n - 1;
      const bool column_inside = c > 0 && c < n - 1;
      if (!row_inside && !column_inside) continue;  // corners depend on the diagonal
      const double expected = row_inside && column_inside ? h * h : 0.5 * h * h;
      // A few cotangents of 45 and 90 degrees, exact up to rounding.
      EXPECT_NEAR(mass(r * n + c), expected, 1e-14) << "row " << r << " column " << c;
    }
  }
}

TEST(MassMatrixTest, EquilateralTriangleSharesEqually) {
  const IndexedMesh triangle = single_triangle(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 0, 0),
                                               Eigen::Vector3d(1, std::sqrt(3.0), 0));
  const double area = std::sqrt(3.0);
  const Eigen::VectorXd mass = mass_matrix(triangle.V, triangle.F).diagonal();
  // Rounding of cot 60 degrees and of sqrt(3).
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mass(k), area / 3.0, 1e-15) << k;
}

TEST(MassMatrixTest, ObtuseTriangleGivesHalfToTheObtuseCorner) {
  // Obtuse at vertex 2 (the apex of a flat isosceles triangle).
  const IndexedMesh triangle = single_triangle(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 0, 0),
                                               Eigen::Vector3d(2, 0.5, 0));
  const double area = 1.0;
  const Eigen::VectorXd voronoi = mass_matrix(triangle.V, triangle.F).diagonal();
  // Exact binary fractions of an exactly computed area.
  EXPECT_DOUBLE_EQ(voronoi(2), area / 2.0);
  EXPECT_DOUBLE_EQ(voronoi(0), area / 4.0);
  EXPECT_DOUBLE_EQ(voronoi(1), area / 4.0);
  const Eigen::VectorXd barycentric =
      mass_matrix(triangle.V, triangle.F, MassType::kBarycentric).diagonal();
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(barycentric(k), area / 3.0);
}

TEST(MassMatrixTest, DegenerateTrianglesGiveFiniteZeroMass) {
  IndexedMesh mesh = single_triangle(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1),
                                     Eigen::Vector3d(3, 3, 3));  // collinear
  mesh.F.conservativeResize(2, 3);
  mesh.F.row(1) << 0, 0, 2;  // repeated index
  for (const MassType type : {MassType::kBarycentric, MassType::kVoronoi}) {
    const Eigen::VectorXd mass = mass_matrix(mesh.V, mesh.F, type).diagonal();
    EXPECT_TRUE(mass.allFinite());
    EXPECT_EQ(mass.cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(MassMatrixTest, RejectsBadIndicesAndCoordinates) {
  IndexedMesh box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  box.F(0, 0) = -1;
  EXPECT_THROW((void)mass_matrix(box.V, box.F), InvalidInputError);
  box = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  box.V(1, 2) = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)mass_matrix(box.V, box.F), InvalidInputError);
}

}  // namespace
}  // namespace mmm::mesh

#include "core/mesh/laplacian.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/errors.h"
#include "core/mesh/mass_matrix.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"

namespace mmm::mesh {
namespace {

using test::make_jittered_grid;

constexpr int kGridSize = 12;
constexpr double kGridSpacing = 2.5;  // mm
// Interior vertices move by up to +-0.2 h: every triangle keeps a positive
// orientation (checked below) and many angles become obtuse.
constexpr double kGridJitter = 0.4;

// The jittered grid placed in a tilted plane away from the origin, so that no
// coordinate axis or zero is special. Returns the rigid map through *rotation
// and *translation.
IndexedMesh tilted_grid(Eigen::Matrix3d* rotation, Eigen::Vector3d* translation) {
  IndexedMesh grid = make_jittered_grid(kGridSize, kGridSpacing, kGridJitter, 7U);
  *rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).matrix();
  *translation = Eigen::Vector3d(100.0, -50.0, 20.0);
  for (Eigen::Index v = 0; v < grid.V.rows(); ++v) {
    grid.V.row(v) = (*rotation * grid.V.row(v).transpose() + *translation).transpose();
  }
  return grid;
}

bool is_boundary_grid_vertex(Eigen::Index v) {
  const Eigen::Index r = v / kGridSize;
  const Eigen::Index c = v % kGridSize;
  return r == 0 || c == 0 || r == kGridSize - 1 || c == kGridSize - 1;
}

double max_abs(const Eigen::SparseMatrix<double>& L) {
  double largest = 0.0;
  for (Eigen::Index col = 0; col < L.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(L, col); it; ++it) {
      largest = std::max(largest, std::abs(it.value()));
    }
  }
  return largest;
}

TEST(CotangentLaplacianTest, JitteredGridTrianglesArePositivelyOriented) {
  // Precondition of the planar tests below: no triangle is flipped.
  const IndexedMesh grid = make_jittered_grid(kGridSize, kGridSpacing, kGridJitter, 7U);
  for (Eigen::Index f = 0; f < grid.F.rows(); ++f) {
    const Eigen::Vector3d a = grid.V.row(grid.F(f, 0)).transpose();
    const Eigen::Vector3d b = grid.V.row(grid.F(f, 1)).transpose();
    const Eigen::Vector3d c = grid.V.row(grid.F(f, 2)).transpose();
    EXPECT_GT((b - a).cross(c - a).z(), 0.05 * kGridSpacing * kGridSpacing) << "face " << f;
  }
}

TEST(CotangentLaplacianTest, LinearFunctionIsHarmonicAtInteriorVerticesOfPlanarMesh) {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  const IndexedMesh grid = tilted_grid(&rotation, &translation);
  const Eigen::Vector3d a(0.3, -1.7, 2.2);
  const double b = -4.0;
  const Eigen::VectorXd f = (grid.V * a).array() + b;
  const Eigen::SparseMatrix<double> L = cotangent_laplacian(grid.V, grid.F);
  const Eigen::VectorXd Lf = L * f;
  // (L f)_i = sum_j L_ij f_j cancels terms of size |L_ij| |f| ~ 5 * 400, so
  // rounding leaves about eps * sum_j |L_ij| * max|f| ~ 1e-14 * max|f|; 1e-10
  // keeps four orders of margin, while one wrong cotangent would leave an
  // error of order |a| h ~ 1e-2 * max|f|.
  const double scale = f.cwiseAbs().maxCoeff();
  double largest_boundary = 0.0;
  for (Eigen::Index v = 0; v < grid.V.rows(); ++v) {
    if (is_boundary_grid_vertex(v)) {
      largest_boundary = std::max(largest_boundary, std::abs(Lf(v)));
    } else {
      EXPECT_LT(std::abs(Lf(v)), 1e-10 * scale) << "interior vertex " << v;
    }
  }
  // On the boundary L f is the conormal derivative, not zero: the test above
  // is not passing because L f vanishes everywhere.
  EXPECT_GT(largest_boundary, 1e-3 * scale);
}

TEST(CotangentLaplacianTest, IcosphereGivesMeanCurvatureNormal) {
  // On a sphere of radius r, -Delta x = 2 H n with H = 1 / r and n outward;
  // the discrete operator is -M^{-1} L with Voronoi masses. Levels 0 and 1 of
  // the icosphere are exact by symmetry (every vertex star is regular); from
  // level 2 on the largest relative error over the vertices must fall at
  // first order in the edge length, i.e. about halve per subdivision (measured
  // ratios 0.50), starting from under 2% (measured 1.67%).
  const double radius = 2.0;  // mm, so that a 1/r error would show
  double previous_error = 0.02;
  for (int level = 2; level <= 6; ++level) {
    const IndexedMesh sphere = make_icosphere(level, radius);
    const Eigen::SparseMatrix<double> L = cotangent_laplacian(sphere.V, sphere.F);
    const Eigen::VectorXd mass = mass_matrix(sphere.V, sphere.F).diagonal();
    const Eigen::MatrixX3d LV = L * sphere.V;
    double error = 0.0;
    for (Eigen::Index v = 0; v < sphere.V.rows(); ++v) {
      const Eigen::Vector3d normal = sphere.V.row(v).transpose() / radius;
      const Eigen::Vector3d curvature_normal = -LV.row(v).transpose() / mass(v);
      error = std::max(error, (curvature_normal - 2.0 / radius * normal).norm() * radius / 2.0);
    }
    EXPECT_LT(error, level == 2 ? previous_error : 0.55 * previous_error) << "level " << level;
    previous_error = error;
  }
}

// Symmetry, zero row sums and x^T L x <= 0 for random x on one mesh.
void expect_laplacian_structure(const Eigen::SparseMatrix<double>& L, const char* label) {
  const double entry_scale = max_abs(L);
  ASSERT_GT(entry_scale, 0.0) << label;
  // Each (i, j) and (j, i) entry is a sum of the same few cotangents, so they
  // agree to a few ulps of the largest entry.
  const Eigen::SparseMatrix<double> transpose = L.transpose();
  EXPECT_LE(max_abs(L - transpose), 1e-14 * entry_scale) << label;
  // The diagonal is minus the sum of the row's off-diagonal terms, summed in
  // another order: rounding of up to ~10 terms of size entry_scale.
  const Eigen::VectorXd row_sums = L * Eigen::VectorXd::Ones(L.cols());
  EXPECT_LE(row_sums.cwiseAbs().maxCoeff(), 1e-13 * entry_scale) << label;
  std::mt19937 rng(42U);
  for (int trial = 0; trial < 10; ++trial) {
    Eigen::VectorXd x(L.cols());
    for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = test::centred_unit(rng);
    // x^T L x = -sum over edges of w_ij (x_i - x_j)^2 summed per triangle as
    // -integral |grad x|^2: strictly negative for a non-constant x.
    EXPECT_LT(x.dot(L * x), 0.0) << label << " trial " << trial;
  }
}

TEST(CotangentLaplacianTest, IsSymmetricWithZeroRowSumsAndNegativeSemidefinite) {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  const IndexedMesh grid = tilted_grid(&rotation, &translation);
  expect_laplacian_structure(cotangent_laplacian(grid.V, grid.F), "jittered grid");
  const IndexedMesh sphere = make_icosphere(3, 5.0);
  expect_laplacian_structure(cotangent_laplacian(sphere.V, sphere.F), "icosphere");
  const IndexedMesh torus = make_torus(30.0, 8.0, 40, 16);
  expect_laplacian_structure(cotangent_laplacian(torus.V, torus.F), "torus");
}

TEST(CotangentLaplacianTest, NegativeWeightFromObtuseAnglesKeepsNegativeSemidefinite) {
  // Two flat triangles on the edge (0, 1) with apex angles near 180 degrees:
  // cot a + cot b < 0, so L(0, 1) is negative, yet the quadratic form is
  // still minus the Dirichlet energy.
  IndexedMesh kite;
  kite.V.resize(4, 3);
  kite.V << 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 1.0, 0.1, 0.0, 1.0, -0.1, 0.0;
  kite.F.resize(2, 3);
  kite.F << 0, 1, 2, 1, 0, 3;
  const Eigen::SparseMatrix<double> L = cotangent_laplacian(kite.V, kite.F);
  // cot of the apex angle: (u . v) / |u x v| with u = (-1, -0.1), v = (1, -0.1).
  const double apex_cot = (-1.0 + 0.01) / 0.2;
  // Only rounding of a handful of products separates the two.
  EXPECT_NEAR(L.coeff(0, 1), apex_cot, 1e-12);
  EXPECT_LT(L.coeff(0, 1), 0.0);
  expect_laplacian_structure(L, "kite");
}

TEST(CotangentLaplacianTest, DirichletEnergyOfLinearFieldIsGradientSquaredTimesArea) {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  const IndexedMesh grid = tilted_grid(&rotation, &translation);
  // A gradient lying in the plane of the mesh.
  const Eigen::Vector3d a = rotation * Eigen::Vector3d(0.8, -1.3, 0.0);
  const Eigen::VectorXd f = (grid.V * a).array() + 3.0;
  const Eigen::SparseMatrix<double> L = cotangent_laplacian(grid.V, grid.F);
  const double area = test::surface_area(grid);
  // Interior jitter does not change the area of the square the grid covers.
  const double side = (kGridSize - 1) * kGridSpacing;
  ASSERT_NEAR(area, side * side, 1e-9 * side * side);
  // Linear elements reproduce a linear field exactly, so only rounding
  // separates the two; the sum has ~1e3 terms of size |f|^2 |L_ij| that
  // cancel down to the energy, hence a relative 1e-9.
  const double energy = -f.dot(L * f);
  EXPECT_NEAR(energy, a.squaredNorm() * area, 1e-9 * f.squaredNorm());
}

TEST(CotangentLaplacianTest, SingleTriangleEntriesAreHalfCotangents) {
  // Right isosceles triangle: angles 90 at corner 0, 45 at corners 1 and 2.
  IndexedMesh triangle;
  triangle.V.resize(3, 3);
  triangle.V << 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 3.0, 0.0;
  triangle.F.resize(1, 3);
  triangle.F << 0, 1, 2;
  const Eigen::MatrixXd L = Eigen::MatrixXd(cotangent_laplacian(triangle.V, triangle.F));
  Eigen::Matrix3d expected;
  // Edge (1, 2) faces the right angle (cot 0); edges (0, 1) and (0, 2) face
  // 45 degrees (cot 1), boundary edges: one term each.
  expected << -1.0, 0.5, 0.5, 0.5, -0.5, 0.0, 0.5, 0.0, -0.5;
  // A few roundings of exactly representable numbers.
  EXPECT_LE((L - expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(CotangentLaplacianTest, DegenerateTrianglesContributeNothing) {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  const IndexedMesh grid = tilted_grid(&rotation, &translation);
  IndexedMesh with_degenerate = grid;
  with_degenerate.F.conservativeResize(grid.F.rows() + 3, 3);
  // Three collinear boundary vertices of the bottom row (collinear before the
  // rigid map; rounding after it leaves an area of ~1e-13 mm^2), a face with
  // a repeated index, and a face on a vertex appended twice.
  with_degenerate.F.row(grid.F.rows()) << 0, 1, 2;
  with_degenerate.F.row(grid.F.rows() + 1) << 5, 5, 6;
  with_degenerate.V.conservativeResize(grid.V.rows() + 1, 3);
  with_degenerate.V.row(grid.V.rows()) = grid.V.row(20);
  with_degenerate.F.row(grid.F.rows() + 2) << 20, static_cast<int>(grid.V.rows()), 21;

  const Eigen::SparseMatrix<double> L = cotangent_laplacian(grid.V, grid.F);
  const Eigen::SparseMatrix<double> L_degenerate =
      cotangent_laplacian(with_degenerate.V, with_degenerate.F);
  ASSERT_EQ(L_degenerate.rows(), grid.V.rows() + 1);
  EXPECT_TRUE(Eigen::MatrixXd(L_degenerate).allFinite());
  // Skipped faces add no term at all, so the shared block is the same sum.
  const Eigen::SparseMatrix<double> shared =
      L_degenerate.topLeftCorner(grid.V.rows(), grid.V.rows());
  EXPECT_EQ(max_abs(shared - L), 0.0);
  EXPECT_EQ(L_degenerate.col(grid.V.rows()).nonZeros(), 0);
}

TEST(CotangentLaplacianTest, RejectsBadIndicesAndCoordinates) {
  const IndexedMesh sphere = make_icosphere(1);
  Eigen::MatrixX3i bad_faces = sphere.F;
  bad_faces(3, 1) = static_cast<int>(sphere.V.rows());
  EXPECT_THROW((void)cotangent_laplacian(sphere.V, bad_faces), InvalidInputError);
  Eigen::MatrixX3d bad_vertices = sphere.V;
  bad_vertices(2, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)cotangent_laplacian(bad_vertices, sphere.F), InvalidInputError);
}

TEST(UniformLaplacianTest, IcosahedronHasValenceFiveEverywhere) {
  const IndexedMesh icosahedron = make_icosphere(0);
  const Eigen::SparseMatrix<double> L = uniform_laplacian(icosahedron.F, 12);
  // 12 diagonal entries plus both directions of the 30 edges.
  EXPECT_EQ(L.nonZeros(), 12 + 60);
  for (Eigen::Index v = 0; v < 12; ++v) EXPECT_EQ(L.coeff(v, v), -5.0) << v;
  for (Eigen::Index f = 0; f < icosahedron.F.rows(); ++f) {
    // Every edge is shared by two faces and still weighs 1.
    EXPECT_EQ(L.coeff(icosahedron.F(f, 0), icosahedron.F(f, 1)), 1.0);
    EXPECT_EQ(L.coeff(icosahedron.F(f, 1), icosahedron.F(f, 0)), 1.0);
  }
  expect_laplacian_structure(L, "uniform icosahedron");
}

TEST(UniformLaplacianTest, OpenMeshCountsEachEdgeOnceAndIgnoresSelfEdges) {
  Eigen::MatrixX3i F(3, 3);
  // A quad (0, 1, 2, 3) split along (0, 2), plus a face repeating vertex 2.
  F << 0, 1, 2, 0, 2, 3, 2, 2, 1;
  const Eigen::SparseMatrix<double> L = uniform_laplacian(F, 5);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(L);
  Eigen::MatrixXd expected(5, 5);
  expected << -3, 1, 1, 1, 0,  //
      1, -2, 1, 0, 0,          //
      1, 1, -3, 1, 0,          //
      1, 0, 1, -2, 0,          //
      0, 0, 0, 0, 0;           // vertex 4 is used by no face
  EXPECT_EQ(dense, expected);
}

TEST(UniformLaplacianTest, RejectsIndicesOutsideTheDeclaredVertexCount) {
  Eigen::MatrixX3i F(1, 3);
  F << 0, 1, 3;
  EXPECT_THROW((void)uniform_laplacian(F, 3), InvalidInputError);
  EXPECT_THROW((void)uniform_laplacian(F, -1), InvalidInputError);
  F << 0, -1, 2;
  EXPECT_THROW((void)uniform_laplacian(F, 3), InvalidInputError);
}

}  // namespace
}  // namespace mmm::mesh

#include "core/fit/principal_axes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/core/fit/fit_test_helpers.h"

namespace mmm::fit {
namespace {

// Sums over a few dozen faces or a few thousand points of coordinates up to
// ~1e3 mm: rounding stays near 1e-13 relative, so 1e-10 is "exact" with a wide
// margin.
constexpr double kExact = 1e-10;

const Eigen::Vector3d kSize(40.0, 20.0, 10.0);  // mm, three distinct extents

// A pose far from the origin, like the VHF meshes.
Eigen::Isometry3d pose() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(610.0, 395.0, 820.0);
  return t;
}

mesh::IndexedMesh transformed_mesh(mesh::IndexedMesh m, const Eigen::Isometry3d& t) {
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    m.V.row(v) = (t * Eigen::Vector3d(m.V.row(v).transpose())).transpose();
  }
  return m;
}

// Both meshes as one (two components).
mesh::IndexedMesh concatenated(const mesh::IndexedMesh& a, const mesh::IndexedMesh& b) {
  mesh::IndexedMesh out;
  out.V.resize(a.V.rows() + b.V.rows(), 3);
  out.V << a.V, b.V;
  out.F.resize(a.F.rows() + b.F.rows(), 3);
  out.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  return out;
}

// |cos| of the angle between two unit vectors is 1 when they are parallel.
void expect_parallel(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  EXPECT_NEAR(std::abs(a.dot(b)), 1.0, kExact) << a.transpose() << " vs " << b.transpose();
}

void expect_rotation(const Eigen::Matrix3d& axes) {
  EXPECT_TRUE((axes.transpose() * axes).isIdentity(kExact));
  EXPECT_NEAR(axes.determinant(), 1.0, kExact);
}

TEST(PrincipalAxesTest, SolidBoxHasKnownAxesAndExtents) {
  const Eigen::Isometry3d t = pose();
  const mesh::IndexedMesh box = transformed_mesh(mesh::make_box(-kSize / 2, kSize / 2), t);
  const PrincipalAxes p = principal_axes(box);
  EXPECT_TRUE(p.centroid.isApprox(t.translation(), kExact));
  // A solid slab of side a: variance a^2 / 12 along it.
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(p.extents[k], kSize[k] / std::sqrt(12.0), kExact * kSize[k]) << k;
    expect_parallel(p.axes.col(k), t.linear().col(k));
    // Symmetric about every axis: no skew (rounding of ~1e-13).
    EXPECT_NEAR(p.skewness[k], 0.0, kExact) << k;
  }
  expect_rotation(p.axes);
  EXPECT_TRUE(p.frame().translation().isApprox(p.centroid));
}

TEST(PrincipalAxesTest, BoxCornersHaveHalfSidesAsExtents) {
  const Eigen::Isometry3d t = pose();
  const mesh::IndexedMesh box = transformed_mesh(mesh::make_box(-kSize / 2, kSize / 2), t);
  const PrincipalAxes p = principal_axes(box.V);
  EXPECT_TRUE(p.centroid.isApprox(t.translation(), kExact));
  // Every corner sits at +-a/2 along each axis: standard deviation a/2.
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(p.extents[k], kSize[k] / 2.0, kExact * kSize[k]) << k;
    expect_parallel(p.axes.col(k), t.linear().col(k));
  }
  expect_rotation(p.axes);
}

TEST(PrincipalAxesTest, PointGridInBoxMatchesDiscreteUniformVariance) {
  // n points per side with spacing h: variance (n^2 - 1) h^2 / 12.
  const Eigen::Vector3i n(21, 11, 6);
  const Eigen::Vector3d h = kSize.cwiseQuotient((n.array() - 1).cast<double>().matrix());
  std::vector<Eigen::Vector3d> grid;
  for (int i = 0; i < n.x(); ++i) {
    for (int j = 0; j < n.y(); ++j) {
      for (int k = 0; k < n.z(); ++k) grid.emplace_back(i * h.x(), j * h.y(), k * h.z());
    }
  }
  Eigen::MatrixX3d points(static_cast<Eigen::Index>(grid.size()), 3);
  for (size_t i = 0; i < grid.size(); ++i) {
    points.row(static_cast<Eigen::Index>(i)) = grid[i].transpose();
  }
  const PrincipalAxes p = principal_axes(points);
  EXPECT_TRUE(p.centroid.isApprox(kSize / 2, kExact));
  for (int k = 0; k < 3; ++k) {
    const double expected = std::sqrt((n[k] * n[k] - 1) / 12.0) * h[k];
    EXPECT_NEAR(p.extents[k], expected, kExact * kSize[k]) << k;
    expect_parallel(p.axes.col(k), Eigen::Vector3d::Unit(k));
  }
}

// Two boxes along x: a 10 mm cube at [0, 10]^3 and a small block at x in
// [30, 40], centred on the cube's y and z axes. Seen along x the solid is a
// mixture of two uniform distributions, whose moments are known in closed form.
struct TwoBoxes {
  mesh::IndexedMesh mesh;
  double mean_x = 0;
  double variance_x = 0;
  double third_moment_x = 0;
};

TwoBoxes two_boxes() {
  const Eigen::Vector3d big_lo(0, 0, 0), big_hi(10, 10, 10);
  const Eigen::Vector3d small_lo(30, 2.5, 4), small_hi(40, 7.5, 6);
  TwoBoxes out;
  out.mesh = concatenated(mesh::make_box(big_lo, big_hi), mesh::make_box(small_lo, small_hi));
  const double big = (big_hi - big_lo).prod();
  const double small = (small_hi - small_lo).prod();
  const double p_big = big / (big + small);
  const double p_small = small / (big + small);
  // Uniform on [a, b]: mean m, variance (b - a)^2 / 12, and about any point mu
  // E[(x - mu)^3] = (m - mu)^3 + 3 (m - mu) variance.
  const double m_big = 5, m_small = 35, var = 100.0 / 12.0;
  out.mean_x = p_big * m_big + p_small * m_small;
  const double d_big = m_big - out.mean_x, d_small = m_small - out.mean_x;
  out.variance_x = p_big * (d_big * d_big + var) + p_small * (d_small * d_small + var);
  out.third_moment_x = p_big * (std::pow(d_big, 3) + 3 * d_big * var) +
                       p_small * (std::pow(d_small, 3) + 3 * d_small * var);
  return out;
}

TEST(PrincipalAxesTest, SolidThirdMomentMatchesClosedForm) {
  const TwoBoxes shape = two_boxes();
  const PrincipalAxes p = principal_axes(shape.mesh);
  EXPECT_NEAR(p.centroid.x(), shape.mean_x, kExact * 40);
  EXPECT_NEAR(p.extents[0], std::sqrt(shape.variance_x), kExact * 40);
  // The long tail (the small block) is at +x, so axis 0 is +x exactly.
  EXPECT_TRUE(p.axes.col(0).isApprox(Eigen::Vector3d::UnitX(), kExact));
  EXPECT_NEAR(p.skewness[0], shape.third_moment_x / std::pow(shape.variance_x, 1.5), kExact);
  // Symmetric about y = 5: no skew along axis 1, whose sign then comes from
  // its largest component: +y.
  EXPECT_NEAR(p.skewness[1], 0.0, kExact);
  EXPECT_TRUE(p.axes.col(1).isApprox(Eigen::Vector3d::UnitY(), kExact));
  expect_rotation(p.axes);
}

TEST(PrincipalAxesTest, SkewedAxisFollowsTheShapeNotThePose) {
  const TwoBoxes shape = two_boxes();
  const Eigen::Isometry3d t = pose();
  const PrincipalAxes solid = principal_axes(transformed_mesh(shape.mesh, t));
  // Rounding only (see kExact).
  EXPECT_TRUE(solid.axes.col(0).isApprox(t.linear().col(0), kExact));
  EXPECT_TRUE(solid.centroid.isApprox(t * Eigen::Vector3d(shape.mean_x, 5, 5), kExact));

  // Same for a point set: the cube's corners and the block's corners, the
  // block's weighted down so that it stays the thin tail (equal weights would
  // balance the two ends exactly).
  const mesh::IndexedMesh moved = transformed_mesh(shape.mesh, t);
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(moved.V.rows());
  weights.tail(8).setConstant(0.5);
  const PrincipalAxes points = principal_axes(moved.V, weights);
  EXPECT_TRUE(points.axes.col(0).isApprox(t.linear().col(0), kExact));
  EXPECT_GT(points.skewness[0], 0.0);
}

TEST(PrincipalAxesTest, ZeroWeightPointsAreIgnored) {
  const mesh::IndexedMesh box = mesh::make_box(-kSize / 2, kSize / 2);
  Eigen::MatrixX3d points(9, 3);
  points << box.V, Eigen::RowVector3d(1000, -500, 30);
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(9);
  weights[8] = 0;
  const PrincipalAxes p = principal_axes(points, weights);
  EXPECT_TRUE(p.centroid.isZero(kExact));
  EXPECT_NEAR(p.extents[0], kSize[0] / 2.0, kExact * kSize[0]);
}

TEST(PrincipalAxesTest, InvalidInputIsRejected) {
  const Eigen::MatrixX3d points = mesh::make_box(-kSize / 2, kSize / 2).V;
  EXPECT_THROW(principal_axes(Eigen::MatrixX3d(0, 3)), InvalidInputError);
  EXPECT_THROW(principal_axes(points, Eigen::VectorXd::Ones(3)), InvalidInputError);
  EXPECT_THROW(principal_axes(points, Eigen::VectorXd::Zero(8)), InvalidInputError);
  Eigen::VectorXd negative = Eigen::VectorXd::Ones(8);
  negative[2] = -1;
  EXPECT_THROW(principal_axes(points, negative), InvalidInputError);
  Eigen::MatrixX3d nan = points;
  nan(3, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(principal_axes(nan), InvalidInputError);
}

TEST(PrincipalAxesTest, OpenMeshIsRejected) {
  mesh::IndexedMesh open = mesh::make_box(-kSize / 2, kSize / 2);
  open.F.conservativeResize(2, 3);  // one side only: a flat square
  EXPECT_THROW(principal_axes(open), InvalidInputError);
  EXPECT_THROW(principal_axes(mesh::IndexedMesh{}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fit

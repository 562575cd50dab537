// Surface patches from fibres: the interpolating cubic spline keeps collinear
// points on their line and follows a circular arc closely; a patch through
// parallel straight fibres in a plane is that rectangle exactly, and one
// through fibres on a cylinder stays on the cylinder.

#include "core/fibres/surface_patch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"

namespace mmm::fibres {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;

// A straight fibre from a to b as a degree-1 t-polynomial.
TPolynomial straight_polynomial(const Vector3d& a, const Vector3d& b) {
  MatrixXd coefficients(2, 3);
  coefficients.row(0) = a.transpose();
  coefficients.row(1) = (b - a).transpose();
  return TPolynomial(coefficients);
}

TEST(SurfacePatchTest, ASplineThroughCollinearPointsStaysOnTheirLine) {
  MatrixXd points(4, 3);
  points << 0, 0, 0, 1, 2, 2, 4, 8, 8, 5, 10, 10;  // uneven steps along (1, 2, 2)
  const MatrixXd samples = cubic_spline(points, 16);
  const Vector3d direction = Vector3d(1, 2, 2).normalized();
  for (Eigen::Index s = 0; s < samples.rows(); ++s) {
    const Vector3d p = samples.row(s).transpose();
    EXPECT_LT((p - p.dot(direction) * direction).norm(), 1e-12) << s;
    EXPECT_NEAR(p.norm(), 15.0 * s / 15.0, 1e-12) << s;  // equal steps of length
  }
}

TEST(SurfacePatchTest, ASplineThroughPointsOfACircularArcFollowsIt) {
  const int k = 7;
  MatrixXd points(k, 3);
  for (int i = 0; i < k; ++i) {
    const double angle = 0.5 * std::numbers::pi * i / (k - 1);
    points.row(i) << 30 * std::cos(angle), 30 * std::sin(angle), 0;
  }
  const MatrixXd samples = cubic_spline(points, 91);
  // Through every point (the knots fall on every 15th sample: equal chords).
  for (int i = 0; i < k; ++i)
    EXPECT_LT((samples.row(Eigen::Index{15} * i) - points.row(i)).norm(), 1e-9) << i;
  // Off the arc by a small fraction of a millimetre, least in the middle
  // (measured: 0.005 mm at most, 0.0002 mm in the middle).
  double worst = 0.0;
  double middle = 0.0;
  for (Eigen::Index s = 0; s < samples.rows(); ++s) {
    const double off = std::abs(samples.row(s).norm() - 30.0);
    worst = std::max(worst, off);
    if (s >= 30 && s <= 60) middle = std::max(middle, off);
  }
  EXPECT_LT(worst, 0.11);  // mm, of a 47 mm arc through 7 points
  EXPECT_LT(middle, 0.01);
  EXPECT_LT((samples.row(0) - points.row(0)).norm(), 1e-12);
  EXPECT_LT((samples.row(90) - points.row(k - 1)).norm(), 1e-12);
}

TEST(SurfacePatchTest, ParallelFibresInAPlaneGiveThatRectangle) {
  std::vector<TPolynomial> fibres;
  for (const double x : {0.0, 10.0, 20.0, 30.0})
    fibres.push_back(straight_polynomial(Vector3d(x, 0, 0), Vector3d(x, 80, 0)));
  const mesh::IndexedMesh patch = fibre_surface_patch(fibres, 9, 7);
  EXPECT_EQ(patch.V.rows(), 63);
  EXPECT_EQ(patch.F.rows(), 2 * 8 * 6);
  EXPECT_LT(patch.V.col(2).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(mesh::surface_area(patch), 30.0 * 80.0, 1e-9);
  // Faces all turn the same way (normals along -z or all along +z).
  double signed_area = 0.0;
  for (Eigen::Index f = 0; f < patch.F.rows(); ++f) {
    const Vector3d a = patch.V.row(patch.F(f, 0)).transpose();
    const Vector3d b = patch.V.row(patch.F(f, 1)).transpose();
    const Vector3d c = patch.V.row(patch.F(f, 2)).transpose();
    signed_area += 0.5 * (b - a).cross(c - a).z();
  }
  EXPECT_NEAR(std::abs(signed_area), 30.0 * 80.0, 1e-9);
}

TEST(SurfacePatchTest, FibresOnACylinderGiveAPatchOnTheCylinder) {
  std::vector<TPolynomial> fibres;
  for (int k = 0; k <= 6; ++k) {
    const double angle = std::numbers::pi * k / 6.0;
    const Vector3d around(25 * std::cos(angle), 25 * std::sin(angle), 0);
    fibres.push_back(straight_polynomial(around, around + Vector3d(0, 0, 120)));
  }
  const mesh::IndexedMesh patch = fibre_surface_patch(fibres, 5, 61);
  // On the cylinder, least away from the edges (measured: 0.061 mm at most,
  // 0.0024 mm in the middle).
  double worst = 0.0;
  double middle = 0.0;
  for (Eigen::Index v = 0; v < patch.V.rows(); ++v) {
    const double off = std::abs(patch.V.row(v).head<2>().norm() - 25.0);
    worst = std::max(worst, off);
    if (v % 61 >= 20 && v % 61 <= 40) middle = std::max(middle, off);
  }
  EXPECT_LT(worst, 0.35);  // mm, 7 fibres 13 mm apart
  EXPECT_LT(middle, 0.03);
  EXPECT_NEAR(patch.V.col(2).maxCoeff(), 120.0, 1e-12);
}

TEST(SurfacePatchTest, BadInputIsRefused) {
  EXPECT_THROW((void)cubic_spline(MatrixXd::Zero(1, 3), 5), InvalidInputError);
  EXPECT_THROW((void)cubic_spline(MatrixXd::Zero(3, 3), 5), InvalidInputError);
  EXPECT_THROW((void)cubic_spline(MatrixXd::Random(3, 3), 1), InvalidInputError);
  const TPolynomial fibre = straight_polynomial(Vector3d::Zero(), Vector3d(0, 0, 10));
  EXPECT_THROW((void)fibre_surface_patch({fibre}, 5, 5), InvalidInputError);
  EXPECT_THROW((void)fibre_surface_patch({fibre, fibre}, 1, 5), InvalidInputError);
  EXPECT_THROW((void)fibre_surface_patch({fibre, TPolynomial(MatrixXd::Ones(2, 2))}, 5, 5),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::fibres

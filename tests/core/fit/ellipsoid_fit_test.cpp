#include "core/fit/ellipsoid_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "core/errors.h"
#include "tests/core/fit/fit_test_helpers.h"

namespace mmm::fit {
namespace {

using test::gaussian_vector;
using test::unit_direction;

// A calcaneus-sized ellipsoid, turned and placed ~1 m from the origin like
// the atlas meshes.
const Eigen::Vector3d kEllipsoidCentre(590.0, 380.0, 120.0);
const Eigen::Vector3d kEllipsoidSemiAxes(34.0, 22.0, 16.0);
const Eigen::Matrix3d kEllipsoidAxes =
    (Eigen::AngleAxisd(0.5, Eigen::Vector3d(0.3, 1.0, 0.2).normalized())).toRotationMatrix();

// Points of the ellipsoid whose direction from the centre (in its own frame)
// has z above `lowest_z` (-1: the whole surface), moved by noise sigma.
Eigen::MatrixX3d sample_ellipsoid(int count, double lowest_z, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  Eigen::MatrixX3d points(count, 3);
  for (int i = 0; i < count;) {
    const Eigen::Vector3d n = unit_direction(rng);
    if (n.z() < lowest_z) continue;
    const Eigen::Vector3d p =
        kEllipsoidCentre + kEllipsoidAxes * n.cwiseProduct(kEllipsoidSemiAxes);
    points.row(i++) = (p + gaussian_vector(rng, sigma)).transpose();
  }
  return points;
}

// The fitted semi-axis along the true axis `k` (principal directions come in
// any order and sign).
double semi_axis_along(const EllipsoidFitResult& fit, int k, double* alignment) {
  int best = 0;
  for (int j = 1; j < 3; ++j) {
    if (std::abs(fit.axes.col(j).dot(kEllipsoidAxes.col(k))) >
        std::abs(fit.axes.col(best).dot(kEllipsoidAxes.col(k)))) {
      best = j;
    }
  }
  *alignment = std::abs(fit.axes.col(best).dot(kEllipsoidAxes.col(k)));
  return fit.semi_axes[best];
}

TEST(EllipsoidFitTest, ExactPointsOnTwoThirdsOfAnEllipsoidGiveItBack) {
  const EllipsoidFitResult fit = ellipsoid_fit(sample_ellipsoid(600, -0.4, 0.0, 1));
  EXPECT_LT((fit.centre - kEllipsoidCentre).norm(), 1e-5);
  for (int k = 0; k < 3; ++k) {
    double alignment = 0;
    EXPECT_NEAR(semi_axis_along(fit, k, &alignment), kEllipsoidSemiAxes[k], 1e-5) << "axis " << k;
    EXPECT_NEAR(alignment, 1.0, 1e-9) << "axis " << k;
  }
  EXPECT_LT(fit.rms, 1e-6);
  EXPECT_NEAR(fit.axes.determinant(), 1.0, 1e-12);
}

TEST(EllipsoidFitTest, NoisyPointsOnAHalfEllipsoidGiveItWithinTheNoise) {
  const EllipsoidFitResult fit = ellipsoid_fit(sample_ellipsoid(2000, 0.0, 0.2, 2));
  EXPECT_LT((fit.centre - kEllipsoidCentre).norm(), 0.6);
  for (int k = 0; k < 3; ++k) {
    double alignment = 0;
    EXPECT_NEAR(semi_axis_along(fit, k, &alignment), kEllipsoidSemiAxes[k], 0.6) << "axis " << k;
    EXPECT_GT(alignment, std::cos(0.05)) << "axis " << k;  // within 3 degrees
  }
  EXPECT_NEAR(fit.rms, 0.2, 0.05);
}

TEST(EllipsoidFitTest, BadInputIsRefused) {
  EXPECT_THROW((void)ellipsoid_fit(sample_ellipsoid(8, -1.0, 0.0, 3)), InvalidInputError);
  Eigen::MatrixX3d flat = sample_ellipsoid(50, -1.0, 0.0, 4);
  flat.col(2).setConstant(5.0);
  flat = flat * kEllipsoidAxes.transpose();
  EXPECT_THROW((void)ellipsoid_fit(flat), InvalidInputError);
  Eigen::MatrixX3d points = sample_ellipsoid(50, -1.0, 0.0, 5);
  points(3, 0) = std::nan("");
  EXPECT_THROW((void)ellipsoid_fit(points), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fit

#include "core/fit/cylinder_fit.h"

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
using test::open_unit;

// A femoral-condyle-sized cylinder (radius 22 mm, axis tilted from x) placed
// ~1 m from the origin like the atlas meshes.
const Eigen::Vector3d kCylinderAxisPoint(612.0, 405.0, 480.0);
const Eigen::Vector3d kCylinderAxis = Eigen::Vector3d(1.0, 0.15, -0.1).normalized();
constexpr double kCylinderRadius = 22.0;

// Points on the part of the cylinder within `half_angle` of the direction
// `towards` (across the axis), over `length` mm, moved by noise sigma.
Eigen::MatrixX3d sample_cylinder(int count, double half_angle, double length, double sigma,
                                 unsigned seed) {
  std::mt19937 rng(seed);
  const Eigen::Vector3d towards = Eigen::Vector3d(0, -1, 0);  // posterior
  const Eigen::Vector3d u = (towards - towards.dot(kCylinderAxis) * kCylinderAxis).normalized();
  const Eigen::Vector3d v = kCylinderAxis.cross(u);
  Eigen::MatrixX3d points(count, 3);
  for (int i = 0; i < count; ++i) {
    const double angle = (2.0 * open_unit(rng) - 1.0) * half_angle;
    const double along = (open_unit(rng) - 0.5) * length;
    const Eigen::Vector3d p = kCylinderAxisPoint + along * kCylinderAxis +
                              kCylinderRadius * (std::cos(angle) * u + std::sin(angle) * v);
    points.row(i) = (p + gaussian_vector(rng, sigma)).transpose();
  }
  return points;
}

double distance_to_axis(const CylinderFitResult& fit, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - fit.centre;
  return (d - d.dot(fit.axis) * fit.axis).norm();
}

TEST(CylinderFitTest, ExactPointsOnAHalfCylinderGiveItBackFromARoughAxisHint) {
  const Eigen::MatrixX3d points = sample_cylinder(400, std::numbers::pi / 2, 40.0, 0.0, 1);
  const Eigen::Vector3d rough =
      (kCylinderAxis + Eigen::Vector3d(0, 0.2, 0.15)).normalized();  // ~14 deg off
  const CylinderFitResult fit = cylinder_fit(points, rough);
  EXPECT_TRUE(fit.converged);
  EXPECT_NEAR(fit.radius, kCylinderRadius, 1e-6);
  EXPECT_NEAR(std::abs(fit.axis.dot(kCylinderAxis)), 1.0, 1e-10);
  EXPECT_GT(fit.axis.dot(rough), 0.0);  // the hint's sign is kept
  EXPECT_NEAR(distance_to_axis(fit, kCylinderAxisPoint), 0.0, 1e-6);
  EXPECT_NEAR(fit.length, 40.0, 1.0);
  EXPECT_LT(fit.rms, 1e-6);
}

TEST(CylinderFitTest, NoisyPointsOnAQuarterCylinderGiveItWithinTheNoise) {
  // 0.2 mm of noise on a 90-degree patch (a condyle's posterior surface).
  const Eigen::MatrixX3d points = sample_cylinder(1500, std::numbers::pi / 4, 30.0, 0.2, 2);
  const CylinderFitResult fit = cylinder_fit(points, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(fit.radius, kCylinderRadius, 0.3);
  EXPECT_LT(std::acos(std::min(1.0, std::abs(fit.axis.dot(kCylinderAxis)))), 0.01);  // < 0.6 degree
  EXPECT_NEAR(distance_to_axis(fit, kCylinderAxisPoint), 0.0, 0.3);
  EXPECT_NEAR(fit.rms, 0.2, 0.03);  // the noise across the surface
}

TEST(CylinderFitTest, BadInputIsRefused) {
  EXPECT_THROW((void)cylinder_fit(Eigen::MatrixX3d::Zero(4, 3)), InvalidInputError);
  Eigen::MatrixX3d points = sample_cylinder(50, 1.0, 20.0, 0.0, 3);
  EXPECT_THROW((void)cylinder_fit(points, Eigen::Vector3d::Zero()), InvalidInputError);
  points(7, 1) = std::nan("");
  EXPECT_THROW((void)cylinder_fit(points), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fit

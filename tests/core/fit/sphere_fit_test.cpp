#include "core/fit/sphere_fit.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "core/errors.h"
#include "tests/core/fit/fit_test_helpers.h"

namespace mmm::fit {
namespace {

using test::direction_in_cap;
using test::gaussian_vector;
using test::radians;

// A femoral head: radius ~24 mm, placed ~1 m from the origin like the VHF
// meshes, so that the normalisation inside the fit matters.
const Eigen::Vector3d kCenter(612.5, 403.25, 798.0);
constexpr double kRadius = 24.0;

// #P points on the cap of half-angle `half_angle` around `axis`, moved off the
// sphere by isotropic Gaussian noise of standard deviation sigma (mm).
Eigen::MatrixX3d sample_sphere(int count, double half_angle, double sigma, unsigned seed,
                               const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ()) {
  std::mt19937 rng(seed);
  const Eigen::Matrix3d to_axis =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix();
  Eigen::MatrixX3d points(count, 3);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d p = kCenter + kRadius * to_axis * direction_in_cap(rng, half_angle);
    points.row(i) = (p + gaussian_vector(rng, sigma)).transpose();
  }
  return points;
}

// Standard deviation of the maximum-likelihood centre (norm of its error) and
// radius for isotropic noise sigma, from the Fisher information of the
// geometric model at the true sphere: Cov = sigma^2 (J^T J)^-1 with Jacobian
// rows [-n_i^T, -1] (n_i = unit direction of point i from the centre). Normal
// noise moves a point along n_i; tangential noise changes its distance only to
// second order, so this is the standard error of the fit to first order.
struct StandardErrors {
  double center = 0;  // sqrt(trace of the centre covariance), mm
  double radius = 0;  // mm
};

StandardErrors standard_errors(const Eigen::MatrixX3d& points, double sigma) {
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    Eigen::Vector4d row;
    row << -(points.row(i).transpose() - kCenter).normalized(), -1.0;
    information += row * row.transpose();
  }
  const Eigen::Matrix4d covariance = sigma * sigma * information.inverse();
  return {std::sqrt(covariance.topLeftCorner<3, 3>().trace()), std::sqrt(covariance(3, 3))};
}

TEST(SphereFitTest, ExactPointsOnWholeSphereAreRecovered) {
  const Eigen::MatrixX3d points = sample_sphere(200, std::numbers::pi, 0.0, 1);
  const SphereFitResult fit = sphere_fit(points);
  // Exact data: the only error is rounding of coordinates ~1e3 mm (~1e-13 mm
  // each), amplified mildly by the normalisation; 1e-9 mm leaves a wide margin.
  EXPECT_NEAR((fit.center - kCenter).norm(), 0.0, 1e-9);
  EXPECT_NEAR(fit.radius, kRadius, 1e-9);
  EXPECT_NEAR(fit.rms, 0.0, 1e-9);
  EXPECT_TRUE(fit.converged);
}

TEST(SphereFitTest, FourPointsDetermineTheSphere) {
  Eigen::MatrixX3d points(4, 3);
  points.row(0) = (kCenter + kRadius * Eigen::Vector3d::UnitX()).transpose();
  points.row(1) = (kCenter + kRadius * Eigen::Vector3d::UnitY()).transpose();
  points.row(2) = (kCenter + kRadius * Eigen::Vector3d::UnitZ()).transpose();
  points.row(3) = (kCenter - kRadius * Eigen::Vector3d(1, 1, 1).normalized()).transpose();
  const SphereFitResult fit = sphere_fit(points);
  // Exact data again (see ExactPointsOnWholeSphereAreRecovered).
  EXPECT_NEAR((fit.center - kCenter).norm(), 0.0, 1e-9);
  EXPECT_NEAR(fit.radius, kRadius, 1e-9);
}

TEST(SphereFitTest, ExactPointsOnSixtyDegreeCapAreRecovered) {
  // A 60 degree cap (30 degrees either side of its pole), tilted: the kind of
  // patch a femoral-head cartilage segmentation leaves.
  const Eigen::MatrixX3d points =
      sample_sphere(300, radians(30.0), 0.0, 2, Eigen::Vector3d(1, -2, 0.5).normalized());
  const SphereFitResult fit = sphere_fit(points);
  // Exact data: a thin cap conditions the centre worse (the centre moves along
  // the axis with the radius) but rounding stays far below 1e-9 mm.
  EXPECT_NEAR((fit.center - kCenter).norm(), 0.0, 1e-9);
  EXPECT_NEAR(fit.radius, kRadius, 1e-9);
}

TEST(SphereFitTest, NoisyWholeSphereIsWithinFiveStandardErrors) {
  const double sigma = 0.2;  // mm, CT segmentation noise at ~0.5 mm voxels
  const Eigen::MatrixX3d points = sample_sphere(500, std::numbers::pi, sigma, 3);
  const SphereFitResult fit = sphere_fit(points);
  const StandardErrors se = standard_errors(points, sigma);
  // The geometric fit is the maximum-likelihood estimate: its error is about
  // one standard error (3 sigma / sqrt(#P) ~ 0.03 mm for the centre here);
  // five leave chance failures below 1e-4 for any seed.
  EXPECT_LT((fit.center - kCenter).norm(), 5.0 * se.center);
  EXPECT_LT(std::abs(fit.radius - kRadius), 5.0 * se.radius);
  // The residual estimates the noise: the RMS of 500 normal deviates is within
  // 10% of sigma with overwhelming probability (its relative sd is ~3%).
  EXPECT_NEAR(fit.rms, sigma, 0.1 * sigma);
}

TEST(SphereFitTest, NoisySixtyDegreeCapRecoversCentre) {
  const double sigma = 0.1;  // mm, a smooth cartilage surface
  const Eigen::MatrixX3d points =
      sample_sphere(400, radians(30.0), sigma, 4, Eigen::Vector3d(0.3, 0.2, -1).normalized());
  const SphereFitResult fit = sphere_fit(points);
  const StandardErrors se = standard_errors(points, sigma);
  // On a 60 degree cap the centre is poorly determined along the cap's axis
  // (moving it together with the radius barely changes the distances), so
  // its standard error (~0.13 mm here) is ~9x that on a whole sphere. Five
  // standard errors again; and the bound itself must stay clinically useful:
  // a hip centre within 2 mm.
  ASSERT_LT(5.0 * se.center, 2.0);
  EXPECT_LT((fit.center - kCenter).norm(), 5.0 * se.center);
  EXPECT_LT(std::abs(fit.radius - kRadius), 5.0 * se.radius);
  EXPECT_TRUE(fit.converged);
}

TEST(SphereFitTest, GeometricRefinementLowersTheResidualOfTheAlgebraicFit) {
  const Eigen::MatrixX3d points = sample_sphere(400, radians(30.0), 0.3, 5);
  SphereFitOptions algebraic_only;
  algebraic_only.refine = false;
  const SphereFitResult algebraic = sphere_fit(points, algebraic_only);
  const SphereFitResult geometric = sphere_fit(points);
  // Levenberg-Marquardt only accepts steps that lower the geometric cost,
  // starting from the algebraic fit: never worse (up to rounding, 1e-12 mm).
  EXPECT_LE(geometric.rms, algebraic.rms + 1e-12);
  EXPECT_EQ(algebraic.iterations, 0);
  // The algebraic fit shrinks a noisy small cap (Kasa bias: ~2 mm of the
  // 24 mm radius here) far more than the geometric one does.
  EXPECT_LT(algebraic.radius, geometric.radius);
}

TEST(SphereFitTest, TooFewPointsAreRejected) {
  const Eigen::MatrixX3d points = sample_sphere(3, std::numbers::pi, 0.0, 6);
  EXPECT_THROW(sphere_fit(points), InvalidInputError);
}

TEST(SphereFitTest, NonFinitePointIsRejected) {
  Eigen::MatrixX3d points = sample_sphere(10, std::numbers::pi, 0.0, 7);
  points(4, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(sphere_fit(points), InvalidInputError);
  points(4, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(sphere_fit(points), InvalidInputError);
}

TEST(SphereFitTest, CoplanarPointsAreRejected) {
  // A circle of the sphere: every sphere through it fits exactly.
  Eigen::MatrixX3d circle(12, 3);
  for (int i = 0; i < 12; ++i) {
    const double phi = 2.0 * std::numbers::pi * i / 12.0;
    circle.row(i) =
        (kCenter + kRadius * Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0)).transpose();
  }
  EXPECT_THROW(sphere_fit(circle), InvalidInputError);

  // A tilted plane patch.
  const Eigen::Vector3d u = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Vector3d v = u.unitOrthogonal();
  Eigen::MatrixX3d plane(25, 3);
  for (int i = 0; i < 25; ++i) {
    plane.row(i) = (kCenter + static_cast<double>(i % 5) * 3.0 * u + std::floor(i / 5.0) * 2.0 * v)
                       .transpose();
  }
  EXPECT_THROW(sphere_fit(plane), InvalidInputError);
}

TEST(SphereFitTest, CollinearAndCoincidentPointsAreRejected) {
  Eigen::MatrixX3d line(6, 3);
  for (int i = 0; i < 6; ++i) line.row(i) = (kCenter + i * Eigen::Vector3d(1, 1, 0)).transpose();
  EXPECT_THROW(sphere_fit(line), InvalidInputError);

  const Eigen::MatrixX3d same = kCenter.transpose().replicate(5, 1);
  EXPECT_THROW(sphere_fit(same), InvalidInputError);
}

TEST(SphereFitTest, NegativeIterationCountIsRejected) {
  SphereFitOptions options;
  options.max_iterations = -1;
  EXPECT_THROW(sphere_fit(sample_sphere(10, std::numbers::pi, 0.0, 8), options), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fit

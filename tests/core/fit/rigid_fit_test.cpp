#include "core/fit/rigid_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/errors.h"
#include "core/fit/principal_axes.h"
#include "tests/core/fit/fit_test_helpers.h"

namespace mmm::fit {
namespace {

using test::gaussian_vector;
using test::rotation_angle_between;
using test::transformed;

// Closed forms on a few dozen points of coordinates ~1e3 mm: rounding leaves
// ~1e-13 mm; 1e-9 (mm, radians, or relative for scales) is "exact" with a
// wide margin.
constexpr double kClosedFormExact = 1e-9;

// #P points scattered over a bone-sized, bone-shaped region (a 60 x 40 x 400 mm
// box, long along z, around a femur's position in the VHF frame), so the
// three extents differ.
Eigen::MatrixX3d bone_points(int count, unsigned seed) {
  std::mt19937 rng(seed);
  Eigen::MatrixX3d points(count, 3);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d unit(test::open_unit(rng), test::open_unit(rng), test::open_unit(rng));
    const Eigen::Vector3d p =
        Eigen::Vector3d(600, 400, 500) +
        (unit.array() - 0.5).matrix().cwiseProduct(Eigen::Vector3d(60, 40, 400));
    points.row(i) = p.transpose();
  }
  return points;
}

Eigen::Isometry3d known_motion() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(0.2, -1.0, 0.4).normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(-35.0, 12.5, 80.0);
  return t;
}

// Largest distance between the images of the points under a and b (mm): the
// error of a fitted transform where it matters, over the data.
double max_mapping_error(const Eigen::MatrixX3d& points, const Eigen::Affine3d& a,
                         const Eigen::Affine3d& b) {
  return (transformed(points, a) - transformed(points, b)).rowwise().norm().maxCoeff();
}

TEST(RigidFitTest, KnownRigidTransformIsRecovered) {
  const Eigen::MatrixX3d source = bone_points(50, 1);
  const Eigen::Isometry3d truth = known_motion();
  const Eigen::MatrixX3d target = transformed(source, Eigen::Affine3d(truth.matrix()));
  const RigidFitResult fit = rigid_fit(source, target);
  EXPECT_LT(rotation_angle_between(fit.rigid.linear(), truth.linear()), kClosedFormExact);
  EXPECT_LT((fit.rigid.translation() - truth.translation()).norm(), kClosedFormExact);
  EXPECT_DOUBLE_EQ(fit.scale, 1.0);
  EXPECT_TRUE(fit.stretch.isIdentity());
  EXPECT_LT(fit.rms, kClosedFormExact);
  EXPECT_TRUE(fit.transform.matrix().isApprox(truth.matrix(), kClosedFormExact));
}

TEST(RigidFitTest, KnownSimilarityIsRecovered) {
  const Eigen::MatrixX3d source = bone_points(50, 2);
  const double scale = 1.137;
  const Eigen::Affine3d truth = Eigen::Affine3d(known_motion().matrix()) * Eigen::Scaling(scale);
  const Eigen::MatrixX3d target = transformed(source, truth);
  RigidFitOptions options;
  options.model = TransformModel::kSimilarity;
  const RigidFitResult fit = rigid_fit(source, target, options);
  EXPECT_NEAR(fit.scale, scale, kClosedFormExact);
  EXPECT_TRUE(fit.axis_scales.isApproxToConstant(scale, kClosedFormExact));
  EXPECT_LT(rotation_angle_between(fit.rigid.linear(), truth.linear() / scale), kClosedFormExact);
  EXPECT_LT(max_mapping_error(source, fit.transform, truth), kClosedFormExact);
  EXPECT_LT(fit.rms, kClosedFormExact);
  // transform = rigid * stretch.
  EXPECT_TRUE(fit.transform.matrix().isApprox((fit.rigid * Eigen::Affine3d(fit.stretch)).matrix(),
                                              kClosedFormExact));
}

TEST(RigidFitTest, RigidModelIgnoresScaleDifference) {
  // Rigid fit of a scaled copy: the rotation is still exact (Umeyama's R does
  // not depend on the scale) and the residual is the scale mismatch.
  const Eigen::MatrixX3d source = bone_points(40, 3);
  const Eigen::Affine3d truth = Eigen::Affine3d(known_motion().matrix()) * Eigen::Scaling(1.2);
  const RigidFitResult fit = rigid_fit(source, transformed(source, truth));
  EXPECT_LT(rotation_angle_between(fit.rigid.linear(), known_motion().linear()), kClosedFormExact);
  EXPECT_GT(fit.rms, 1.0);  // 20% of a ~100 mm RMS spread is far above 1 mm
}

TEST(RigidFitTest, ZeroWeightIgnoresOutlier) {
  const Eigen::MatrixX3d source = bone_points(30, 4);
  const Eigen::Isometry3d truth = known_motion();
  Eigen::MatrixX3d target = transformed(source, Eigen::Affine3d(truth.matrix()));
  target.row(7) += Eigen::RowVector3d(150.0, -80.0, 40.0);  // a mislabelled landmark
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(30);

  // Unweighted, the outlier pulls the fit away by millimetres.
  const RigidFitResult pulled = rigid_fit(source, target, weights);
  EXPECT_GT(max_mapping_error(source, pulled.transform, Eigen::Affine3d(truth.matrix())), 1.0);

  weights[7] = 0.0;
  const RigidFitResult fit = rigid_fit(source, target, weights);
  EXPECT_LT(max_mapping_error(source, fit.transform, Eigen::Affine3d(truth.matrix())),
            kClosedFormExact);
  // The residual counts only weighted pairs.
  EXPECT_LT(fit.rms, kClosedFormExact);
}

TEST(RigidFitTest, WeightedRmsIsTheWeightedResidual) {
  const Eigen::MatrixX3d source = bone_points(60, 5);
  std::mt19937 rng(5);
  Eigen::MatrixX3d target = transformed(source, Eigen::Affine3d(known_motion().matrix()));
  Eigen::VectorXd weights(60);
  for (int i = 0; i < 60; ++i) {
    target.row(i) += gaussian_vector(rng, 0.5).transpose();
    weights[i] = 0.5 + test::open_unit(rng);
  }
  const RigidFitResult fit = rigid_fit(source, target, weights);
  const Eigen::VectorXd squared =
      (transformed(source, fit.transform) - target).rowwise().squaredNorm();
  // Same sum evaluated two ways: rounding only.
  EXPECT_NEAR(fit.rms, std::sqrt(weights.dot(squared) / weights.sum()), kClosedFormExact);
  // With noise of 0.5 mm per coordinate, the residual is ~0.5 sqrt(3 - 6/60)
  // mm: within 20% for 60 points (relative sd of the RMS is ~5%).
  EXPECT_NEAR(fit.rms, 0.5 * std::sqrt(3.0 - 6.0 / 60.0), 0.2 * 0.85);
  // The worst-determined rotation is the spin about the long (400 mm) axis,
  // whose lever is the 60 x 40 mm cross-section: RMS sqrt((60^2 + 40^2) / 12)
  // ~ 21 mm. Noise of 0.5 mm over 60 points gives an sd of 0.5 / (21 sqrt(60))
  // rad ~ 0.18 degrees; 1 degree is > 5 sd.
  EXPECT_LT(test::degrees(rotation_angle_between(fit.rigid.linear(), known_motion().linear())),
            1.0);
}

TEST(RigidFitTest, ReflectedTargetGivesProperRotation) {
  const Eigen::MatrixX3d source = bone_points(40, 6);
  // The mirror image (a left bone onto a right one): the best rotation is not
  // the reflection.
  Eigen::Affine3d mirror = Eigen::Affine3d::Identity();
  mirror.linear() = Eigen::Vector3d(-1.0, 1.0, 1.0).asDiagonal();
  const Eigen::MatrixX3d target =
      transformed(source, Eigen::Affine3d(known_motion().matrix()) * mirror);
  for (const TransformModel model : {TransformModel::kRigid, TransformModel::kSimilarity}) {
    RigidFitOptions options;
    options.model = model;
    const RigidFitResult fit = rigid_fit(source, target, options);
    const Eigen::Matrix3d r = fit.rigid.linear();
    // Orthonormal with determinant +1 up to rounding.
    EXPECT_TRUE((r.transpose() * r).isIdentity(kClosedFormExact));
    EXPECT_NEAR(r.determinant(), 1.0, kClosedFormExact);
    EXPECT_GT(fit.scale, 0.0);
    EXPECT_GT(fit.rms, 1.0);  // a reflection cannot be undone by a motion
  }
}

TEST(RigidFitTest, ThreePointsSufficeAndPlanarSetsAreFine) {
  Eigen::MatrixX3d source(3, 3);
  source << 0, 0, 0, 50, 0, 0, 0, 30, 0;
  const Eigen::Isometry3d truth = known_motion();
  const RigidFitResult fit =
      rigid_fit(source, transformed(source, Eigen::Affine3d(truth.matrix())));
  EXPECT_TRUE(fit.transform.matrix().isApprox(truth.matrix(), kClosedFormExact));
}

TEST(RigidFitTest, FewerThanThreeNonCollinearPointsAreRejected) {
  Eigen::MatrixX3d two(2, 3);
  two << 0, 0, 0, 1, 0, 0;
  EXPECT_THROW(rigid_fit(two, two), InvalidInputError);

  Eigen::MatrixX3d line(5, 3);
  for (int i = 0; i < 5; ++i) line.row(i) = Eigen::RowVector3d(600 + 10.0 * i, 400 + 5.0 * i, 800);
  EXPECT_THROW(rigid_fit(line, line), InvalidInputError);

  // Three points of positive weight, but collinear; the fourth is off the line
  // with weight 0.
  Eigen::MatrixX3d four(4, 3);
  four << 0, 0, 0, 1, 1, 1, 2, 2, 2, 5, 0, 0;
  EXPECT_THROW(rigid_fit(four, four, Eigen::Vector4d(1, 1, 1, 0)), InvalidInputError);
  EXPECT_NO_THROW(rigid_fit(four, four, Eigen::Vector4d(1, 1, 1, 1)));
  // Only two pairs of positive weight.
  EXPECT_THROW(rigid_fit(four, four, Eigen::Vector4d(1, 0, 1, 0)), InvalidInputError);

  // A collinear target with a spread-out source leaves the rotation free.
  EXPECT_THROW(rigid_fit(four, line.topRows(4)), InvalidInputError);
}

TEST(RigidFitTest, InvalidInputIsRejected) {
  const Eigen::MatrixX3d source = bone_points(10, 7);
  EXPECT_THROW(rigid_fit(source, source.topRows(9)), InvalidInputError);
  EXPECT_THROW(rigid_fit(source, source, Eigen::VectorXd::Ones(9)), InvalidInputError);
  Eigen::VectorXd negative = Eigen::VectorXd::Ones(10);
  negative[3] = -1;
  EXPECT_THROW(rigid_fit(source, source, negative), InvalidInputError);
  Eigen::VectorXd nan_weight = Eigen::VectorXd::Ones(10);
  nan_weight[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(rigid_fit(source, source, nan_weight), InvalidInputError);
  Eigen::MatrixX3d nan = source;
  nan(2, 2) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(rigid_fit(source, nan), InvalidInputError);
  RigidFitOptions skewed;
  skewed.model = TransformModel::kAxisScaled;
  skewed.scale_axes = Eigen::Matrix3d::Identity();
  (*skewed.scale_axes)(0, 1) = 0.1;
  EXPECT_THROW(rigid_fit(source, source, skewed), InvalidInputError);
}

TEST(RigidFitTest, AxisScaledRecoversPerAxisScalesAlongGivenAxes) {
  const Eigen::MatrixX3d source = bone_points(80, 8);
  // Another subject's femur: 8% longer, 3% narrower, 5% deeper, along axes
  // tilted away from the coordinate axes.
  const Eigen::Matrix3d axes =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::Vector3d scales(0.97, 1.05, 1.08);
  const Eigen::Matrix3d stretch = axes * scales.asDiagonal() * axes.transpose();
  const Eigen::Affine3d truth = Eigen::Affine3d(known_motion().matrix()) * Eigen::Affine3d(stretch);
  const Eigen::MatrixX3d target = transformed(source, truth);
  RigidFitOptions options;
  options.model = TransformModel::kAxisScaled;
  options.scale_axes = axes;
  const RigidFitResult fit = rigid_fit(source, target, options);
  EXPECT_TRUE(fit.converged);
  // Levenberg-Marquardt to convergence on exact data: rounding only.
  EXPECT_TRUE(fit.axis_scales.isApprox(scales, kClosedFormExact));
  EXPECT_TRUE(fit.stretch.isApprox(stretch, kClosedFormExact));
  EXPECT_LT(rotation_angle_between(fit.rigid.linear(), known_motion().linear()), kClosedFormExact);
  EXPECT_LT(max_mapping_error(source, fit.transform, truth),
            1e-7);  // kClosedFormExact x ~100 mm lever
  EXPECT_LT(fit.rms, 1e-7);
  EXPECT_NEAR(fit.scale, std::cbrt(scales.prod()), kClosedFormExact);
  EXPECT_TRUE(fit.scale_axes.isApprox(axes));
}

TEST(RigidFitTest, AxisScaledDefaultsToThePrincipalAxesOfTheSource) {
  const Eigen::MatrixX3d source = bone_points(80, 9);
  const Eigen::Matrix3d axes = principal_axes(source).axes;
  const Eigen::Vector3d scales(1.10, 0.92, 1.01);  // long axis first
  const Eigen::Matrix3d stretch = axes * scales.asDiagonal() * axes.transpose();
  const Eigen::Affine3d truth = Eigen::Affine3d(known_motion().matrix()) * Eigen::Affine3d(stretch);
  RigidFitOptions options;
  options.model = TransformModel::kAxisScaled;
  const RigidFitResult fit = rigid_fit(source, transformed(source, truth), options);
  EXPECT_TRUE(fit.scale_axes.isApprox(axes, kClosedFormExact));
  EXPECT_TRUE(fit.axis_scales.isApprox(scales, kClosedFormExact));  // rounding only, as above
  EXPECT_LT(max_mapping_error(source, fit.transform, truth), 1e-7);

  // The similarity fit of the same data cannot follow the proportions.
  options.model = TransformModel::kSimilarity;
  EXPECT_GT(rigid_fit(source, transformed(source, truth), options).rms, 1.0);
}

TEST(RigidFitTest, AxisScaledRejectsAFlatSource) {
  Eigen::MatrixX3d flat = bone_points(20, 10);
  flat.col(2).setConstant(500.0);  // all in one plane: no scale across it
  RigidFitOptions options;
  options.model = TransformModel::kAxisScaled;
  EXPECT_THROW(rigid_fit(flat, flat, options), InvalidInputError);
  options.model = TransformModel::kSimilarity;
  EXPECT_NO_THROW(rigid_fit(flat, flat, options));
}

}  // namespace
}  // namespace mmm::fit

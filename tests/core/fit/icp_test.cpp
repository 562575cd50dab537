#include "core/fit/icp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/core/fit/fit_test_helpers.h"

namespace mmm::fit {
namespace {

using test::degrees;
using test::radians;
using test::rotation_angle_between;
using test::transformed;

// The brief's acceptance bounds for a registration: well below a CT voxel
// (~0.5 mm) and below what a landmark operator can click (~1 mm, ~1 degree).
constexpr double kMaxErrorMm = 0.1;
constexpr double kMaxErrorDegrees = 0.1;

const Eigen::Vector3d kPlace(610.0, 395.0, 820.0);  // ~1 m from the origin, like VHF

// An elongated ellipsoid (semi-axes 50, 25, 18 mm) with a smooth bump of 8 mm
// on one side: no symmetry left, like a bone end with a condyle.
mesh::IndexedMesh bumped_ellipsoid() {
  mesh::IndexedMesh m = mesh::make_icosphere(4);
  const Eigen::Vector3d bump_direction = Eigen::Vector3d(0.6, 0.5, 0.6).normalized();
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    const Eigen::Vector3d u = m.V.row(v).transpose();  // on the unit sphere
    const double angle = std::acos(std::clamp(u.dot(bump_direction), -1.0, 1.0));
    const double bump = 8.0 * std::exp(-angle * angle / (2.0 * 0.3 * 0.3));
    const Eigen::Vector3d p = u.cwiseProduct(Eigen::Vector3d(50, 25, 18)) + bump * u;
    m.V.row(v) = (kPlace + p).transpose();
  }
  return m;
}

// #P points uniform over the surface (area-weighted faces, uniform
// barycentric coordinates): not the vertices, so no source point sits on a
// mesh vertex. The unit outward normals of their faces go to *normals.
Eigen::MatrixX3d surface_samples(const mesh::IndexedMesh& m, int count, unsigned seed,
                                 Eigen::MatrixX3d* normals = nullptr) {
  std::mt19937 rng(seed);
  std::vector<double> cumulative(static_cast<size_t>(m.F.rows()));
  double total = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)).transpose();
    const Eigen::Vector3d b = m.V.row(m.F(f, 1)).transpose();
    const Eigen::Vector3d c = m.V.row(m.F(f, 2)).transpose();
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative[static_cast<size_t>(f)] = total;
  }
  Eigen::MatrixX3d points(count, 3);
  if (normals != nullptr) normals->resize(count, 3);
  for (int i = 0; i < count; ++i) {
    const double pick = test::open_unit(rng) * total;
    const auto f = static_cast<Eigen::Index>(
        std::lower_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin());
    double s = test::open_unit(rng);
    double t = test::open_unit(rng);
    if (s + t > 1) {
      s = 1 - s;
      t = 1 - t;
    }
    const Eigen::RowVector3d a = m.V.row(m.F(f, 0));
    const Eigen::RowVector3d b = m.V.row(m.F(f, 1));
    const Eigen::RowVector3d c = m.V.row(m.F(f, 2));
    points.row(i) = (1 - s - t) * a + s * b + t * c;
    if (normals != nullptr) normals->row(i) = (b - a).cross(c - a).normalized();
  }
  return points;
}

// A motion of `angle_degrees` about an oblique axis through the shape's centre
// followed by a shift of `shift_mm`.
Eigen::Affine3d motion(double angle_degrees, double shift_mm, double scale = 1.0) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const Eigen::Vector3d shift = shift_mm * Eigen::Vector3d(1.0, 2.0, -1.5).normalized();
  return Eigen::Translation3d(kPlace + shift) * Eigen::AngleAxisd(radians(angle_degrees), axis) *
         Eigen::Scaling(scale) * Eigen::Translation3d(-kPlace);
}

// Registration error over the source: the largest distance between where the
// fit and the truth send a source point (mm), and the rotation error (degrees).
struct Errors {
  double mm = 0;
  double degrees = 0;
};

Errors errors(const Eigen::MatrixX3d& source, const IcpResult& fit, const Eigen::Affine3d& truth) {
  Errors e;
  e.mm =
      (transformed(source, fit.transform) - transformed(source, truth)).rowwise().norm().maxCoeff();
  const double truth_scale = std::cbrt(truth.linear().determinant());
  e.degrees = degrees(rotation_angle_between(fit.rigid.linear(), truth.linear() / truth_scale));
  return e;
}

// Source = target samples pulled back by the inverse of `truth`: ICP must find
// `truth`.
Eigen::MatrixX3d moved_source(const mesh::IndexedMesh& target, const Eigen::Affine3d& truth,
                              int count, unsigned seed) {
  return transformed(surface_samples(target, count, seed), truth.inverse());
}

TEST(IcpTest, PointToPlaneRecoversKnownRigidMotion) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  const Eigen::Affine3d truth = motion(10.0, 20.0);
  const Eigen::MatrixX3d source = moved_source(target, truth, 600, 1);
  const IcpResult fit = icp(source, tree);
  const Errors e = errors(source, fit, truth);
  EXPECT_TRUE(fit.converged);
  EXPECT_LT(e.mm, kMaxErrorMm);
  EXPECT_LT(e.degrees, kMaxErrorDegrees);
  // The samples lie exactly on the target: the converged residual is limited
  // only by the RMS-change tolerance (1e-6 mm by default).
  EXPECT_LT(fit.rms, 1e-4);
  EXPECT_EQ(fit.distances.size(), 600);
  EXPECT_EQ(fit.kept.count(), 600);
  EXPECT_DOUBLE_EQ(fit.scale, 1.0);
}

TEST(IcpTest, PointToPointRecoversKnownRigidMotion) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  const Eigen::Affine3d truth = motion(10.0, 20.0);
  const Eigen::MatrixX3d source = moved_source(target, truth, 600, 2);
  IcpOptions options;
  options.metric = IcpOptions::Metric::kPointToPoint;
  // Point-to-point converges linearly (each step moves a fraction of the
  // remaining way along the surface): give it room and a tight stop.
  options.max_iterations = 500;
  options.rms_tolerance = 1e-8;
  const IcpResult fit = icp(source, tree, options);
  const Errors e = errors(source, fit, truth);
  EXPECT_TRUE(fit.converged);
  EXPECT_LT(e.mm, kMaxErrorMm);
  EXPECT_LT(e.degrees, kMaxErrorDegrees);
}

TEST(IcpTest, PointToPlaneNeedsFewerIterationsThanPointToPoint) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  const Eigen::MatrixX3d source = moved_source(target, motion(10.0, 20.0), 400, 3);
  IcpOptions options;
  options.max_iterations = 500;
  const IcpResult plane = icp(source, tree, options);
  options.metric = IcpOptions::Metric::kPointToPoint;
  const IcpResult point = icp(source, tree, options);
  EXPECT_LT(plane.iterations, point.iterations);
}

TEST(IcpTest, SimilarityRecoversScale) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  const double scale = 1.08;  // a bone 8% larger
  const Eigen::Affine3d truth = motion(6.0, 10.0, scale);
  const Eigen::MatrixX3d source = moved_source(target, truth, 600, 4);
  IcpOptions options;
  options.model = TransformModel::kSimilarity;
  const IcpResult fit = icp(source, tree, options);
  const Errors e = errors(source, fit, truth);
  EXPECT_TRUE(fit.converged);
  EXPECT_LT(e.mm, kMaxErrorMm);
  EXPECT_LT(e.degrees, kMaxErrorDegrees);
  // 0.1 mm over the 50 mm semi-axis is a relative scale error of 2e-3.
  EXPECT_NEAR(fit.scale, scale, kMaxErrorMm / 50.0);
  EXPECT_TRUE(fit.stretch.isApprox(fit.scale * Eigen::Matrix3d::Identity(), 1e-12));

  // The rigid model cannot: it is left with millimetres of residual.
  const IcpResult rigid = icp(source, tree);
  EXPECT_GT(rigid.rms, 0.5);
}

TEST(IcpTest, AxisScaledPointToPointRecoversProportions) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  const Eigen::Vector3d scales(1.06, 0.95, 1.0);
  const Eigen::Affine3d truth = motion(4.0, 5.0) * Eigen::Translation3d(kPlace) *
                                Eigen::Affine3d(Eigen::Matrix3d(scales.asDiagonal())) *
                                Eigen::Translation3d(-kPlace);
  const Eigen::MatrixX3d source = moved_source(target, truth, 800, 5);
  IcpOptions options;
  options.metric = IcpOptions::Metric::kPointToPoint;
  options.model = TransformModel::kAxisScaled;
  options.scale_axes = Eigen::Matrix3d::Identity();  // the ellipsoid's own axes
  options.max_iterations = 500;
  options.rms_tolerance = 1e-8;
  const IcpResult fit = icp(source, tree, options);
  EXPECT_LT(errors(source, fit, truth).mm, kMaxErrorMm);
  // The stretch is A diag(s) A^T with A = I: the scales on the diagonal,
  // within 0.1 mm over a ~25-50 mm semi-axis (4e-3 relative).
  EXPECT_TRUE(fit.stretch.diagonal().isApprox(scales, 4e-3));
}

TEST(IcpTest, LandmarksResolveTheSymmetricSphere) {
  // A sphere turned about its centre: every point still lies on it, so the
  // surface alone cannot tell the rotation.
  const mesh::IndexedMesh target = mesh::make_icosphere(4, 25.0, kPlace);
  const mesh::AabbTree tree(target);
  const Eigen::Affine3d truth = motion(30.0, 5.0);
  const Eigen::MatrixX3d source = moved_source(target, truth, 500, 6);

  const IcpResult alone = icp(source, tree);
  // ICP finds the shift but stays at the wrong rotation: ~30 degrees off.
  EXPECT_GT(errors(source, alone, truth).degrees, 20.0);

  // Three anatomical landmarks on the source with their known positions on the
  // target, each weighted like 10 surface points.
  std::vector<LandmarkPair> landmarks;
  for (const int i : {0, 100, 200}) {
    const Eigen::Vector3d a = source.row(i).transpose();
    landmarks.push_back({a, truth * a, 10.0});
  }
  for (const auto metric : {IcpOptions::Metric::kPointToPlane, IcpOptions::Metric::kPointToPoint}) {
    IcpOptions options;
    options.metric = metric;
    options.max_iterations = 500;
    options.rms_tolerance = 1e-8;
    const IcpResult anchored = icp(source, Eigen::VectorXd(), tree, landmarks, options);
    const Errors e = errors(source, anchored, truth);
    EXPECT_TRUE(anchored.converged);
    EXPECT_LT(e.mm, kMaxErrorMm);
    EXPECT_LT(e.degrees, kMaxErrorDegrees);
    EXPECT_LT(anchored.landmark_rms, kMaxErrorMm);
  }
}

// Like moved_source, with the last tenth of the samples pushed 15-30 mm off
// the target along its outward normal before the pull-back (a segmentation
// leak). Also returns the clean source in *clean.
Eigen::MatrixX3d source_with_outliers(const mesh::IndexedMesh& target, const Eigen::Affine3d& truth,
                                      int count, unsigned seed, Eigen::MatrixX3d* clean) {
  Eigen::MatrixX3d normals;
  Eigen::MatrixX3d samples = surface_samples(target, count, seed, &normals);
  *clean = transformed(samples, truth.inverse());
  std::mt19937 rng(seed);
  for (int i = count - count / 10; i < count; ++i) {
    samples.row(i) += (15.0 + 15.0 * test::open_unit(rng)) * normals.row(i);
  }
  return transformed(samples, truth.inverse());
}

TEST(IcpTest, TrimmingRejectsOutliers) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  const Eigen::Affine3d truth = motion(10.0, 20.0);
  Eigen::MatrixX3d clean;
  const Eigen::MatrixX3d source = source_with_outliers(target, truth, 600, 7, &clean);

  const IcpResult pulled = icp(source, tree);
  EXPECT_GT(errors(clean, pulled, truth).mm, kMaxErrorMm);

  IcpOptions options;
  options.trim_fraction = 0.15;  // 10% outliers plus a margin
  const IcpResult fit = icp(source, tree, options);
  const Errors e = errors(clean, fit, truth);
  EXPECT_LT(e.mm, kMaxErrorMm);
  EXPECT_LT(e.degrees, kMaxErrorDegrees);
  EXPECT_EQ(fit.kept.count(), 600 - 90);  // floor(0.15 * 600) dropped
  // Every outlier is among the dropped, and reported at its true distance:
  // pushed >= 15 mm along the normal of a surface whose radii of curvature
  // are ~10 mm or more, it stays well over 5 mm from every part of it.
  EXPECT_FALSE(fit.kept.tail(60).any());
  EXPECT_GT(fit.distances.tail(60).minCoeff(), 5.0);
}

TEST(IcpTest, MaxDistanceRejectsOutliers) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  // A small motion, as after a landmark-based initial alignment: the inliers
  // start within the 10 mm gate.
  const Eigen::Affine3d truth = motion(3.0, 3.0);
  Eigen::MatrixX3d clean;
  const Eigen::MatrixX3d source = source_with_outliers(target, truth, 600, 8, &clean);
  IcpOptions options;
  options.max_distance = 10.0;
  const IcpResult fit = icp(source, tree, options);
  const Errors e = errors(clean, fit, truth);
  EXPECT_LT(e.mm, kMaxErrorMm);
  EXPECT_LT(e.degrees, kMaxErrorDegrees);
  EXPECT_EQ(fit.kept.head(540).count(), 540);
}

TEST(IcpTest, ZeroWeightsLeaveOutliersOut) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  const Eigen::Affine3d truth = motion(10.0, 20.0);
  Eigen::MatrixX3d clean;
  const Eigen::MatrixX3d source = source_with_outliers(target, truth, 600, 9, &clean);
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(600);
  weights.tail(60).setZero();
  const IcpResult fit = icp(source, weights, tree, {});
  EXPECT_LT(errors(clean, fit, truth).mm, kMaxErrorMm);
  EXPECT_EQ(fit.kept.count(), 540);
}

TEST(IcpTest, InitialTransformIsUsed) {
  const mesh::IndexedMesh target = bumped_ellipsoid();
  const mesh::AabbTree tree(target);
  const Eigen::Affine3d truth = motion(10.0, 20.0);
  const Eigen::MatrixX3d source = moved_source(target, truth, 300, 10);
  IcpOptions options;
  options.initial = truth;
  options.max_iterations = 0;
  const IcpResult fit = icp(source, tree, options);
  EXPECT_EQ(fit.iterations, 0);
  EXPECT_TRUE(fit.transform.isApprox(truth));
  // The samples lie on the target (rounding of ~1e-13 mm).
  EXPECT_LT(fit.distances.maxCoeff(), 1e-9);
}

TEST(IcpTest, InvalidInputIsRejected) {
  const mesh::AabbTree tree(mesh::make_icosphere(2, 10.0));
  const Eigen::MatrixX3d source = surface_samples(tree.mesh(), 20, 11);
  EXPECT_THROW(icp(source, Eigen::VectorXd::Ones(19), tree, {}), InvalidInputError);
  Eigen::VectorXd negative = Eigen::VectorXd::Ones(20);
  negative[0] = -1;
  EXPECT_THROW(icp(source, negative, tree, {}), InvalidInputError);
  Eigen::MatrixX3d nan = source;
  nan(3, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(icp(nan, tree), InvalidInputError);
  const std::vector<LandmarkPair> bad_landmark{
      {Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(std::nan("")), 1.0}};
  EXPECT_THROW(icp(source, Eigen::VectorXd(), tree, bad_landmark), InvalidInputError);

  const auto rejects = [&](const IcpOptions& options) {
    EXPECT_THROW(icp(source, tree, options), InvalidInputError);
  };
  IcpOptions o;
  o.trim_fraction = 1.0;
  rejects(o);
  o = {};
  o.max_distance = 0;
  rejects(o);
  o = {};
  o.max_iterations = -1;
  rejects(o);
  o = {};
  o.model = TransformModel::kAxisScaled;  // with the default point-to-plane
  rejects(o);
  o = {};
  o.initial = Eigen::Scaling(1.1);  // a scale for the rigid model
  rejects(o);
  o = {};
  o.initial = Eigen::Affine3d(Eigen::Matrix3d(Eigen::Vector3d(-1, 1, 1).asDiagonal()));
  o.model = TransformModel::kSimilarity;  // a reflection
  rejects(o);
}

TEST(IcpTest, TooFewPairsIsASolverError) {
  const mesh::AabbTree tree(mesh::make_icosphere(2, 10.0));
  // All source points 50 mm away from the surface, none within max_distance.
  const Eigen::MatrixX3d source = surface_samples(tree.mesh(), 20, 12) * 6.0;
  IcpOptions options;
  options.max_distance = 5.0;
  EXPECT_THROW(icp(source, tree, options), SolverError);
}

}  // namespace
}  // namespace mmm::fit

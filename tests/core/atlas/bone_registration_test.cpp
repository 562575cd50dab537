#include "core/atlas/bone_registration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/primitives.h"

namespace mmm::atlas {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// A bone-like shape without any symmetry: an ellipsoid (semi-axes 30, 18,
// 10 mm) with two bumps of different sizes off its axes, so that ICP has one
// answer near the start. Vertices: 642 + 162 + 42.
mesh::IndexedMesh asymmetric_shape() {
  mesh::IndexedMesh ellipsoid = mesh::make_icosphere(3, 1.0);
  ellipsoid.V = ellipsoid.V * Eigen::Vector3d(30, 18, 10).asDiagonal();
  const mesh::IndexedMesh bump = mesh::make_icosphere(2, 7.0, Eigen::Vector3d(22, 9, 5));
  const mesh::IndexedMesh knob = mesh::make_icosphere(1, 4.0, Eigen::Vector3d(-20, -8, 7));
  mesh::IndexedMesh shape;
  shape.V.resize(ellipsoid.num_vertices() + bump.num_vertices() + knob.num_vertices(), 3);
  shape.V << ellipsoid.V, bump.V, knob.V;
  shape.F.resize(ellipsoid.num_faces() + bump.num_faces() + knob.num_faces(), 3);
  const int bump_offset = static_cast<int>(ellipsoid.num_vertices());
  const int knob_offset = bump_offset + static_cast<int>(bump.num_vertices());
  shape.F << ellipsoid.F, (bump.F.array() + bump_offset).matrix(),
      (knob.F.array() + knob_offset).matrix();
  return shape;
}

mesh::IndexedMesh mapped(const mesh::IndexedMesh& mesh, const Eigen::Affine3d& map) {
  mesh::IndexedMesh result = mesh;
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    result.V.row(v) = (map * Eigen::Vector3d(mesh.V.row(v).transpose())).transpose();
  }
  return result;
}

Eigen::Affine3d similarity(double scale, double angle, const Eigen::Vector3d& axis,
                           const Eigen::Vector3d& translation) {
  Eigen::Affine3d map = Eigen::Affine3d::Identity();
  map.linear() = scale * Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  map.translation() = translation;
  return map;
}

// Largest distance between the two maps' images of the shape's vertices: a
// map error measured where it matters (mm).
double max_map_difference(const Eigen::Affine3d& a, const Eigen::Affine3d& b,
                          const mesh::IndexedMesh& shape) {
  double worst = 0.0;
  for (Eigen::Index v = 0; v < shape.num_vertices(); ++v) {
    const Eigen::Vector3d p = shape.V.row(v).transpose();
    worst = std::max(worst, (a * p - b * p).norm());
  }
  return worst;
}

TEST(BoneRegistrationTest, RecoversAKnownSimilarityOfAnAsymmetricShape) {
  const mesh::IndexedMesh shape = asymmetric_shape();
  const Eigen::Affine3d truth =
      similarity(1.08, 8 * kDegree, Eigen::Vector3d(1, 2, -1), Eigen::Vector3d(3, -2, 4));
  const mesh::AabbTree target(mapped(shape, truth));
  RegistrationOptions options;
  options.anisotropic = false;
  const RegistrationResult result =
      register_points(shape.V, &target, {}, Eigen::Affine3d::Identity(), options);
  // The source maps exactly onto the target, so ICP's fixed point has zero
  // residual; 40 point-to-point steps from an 8 degree / 5 mm start get
  // within a few hundredths of a mm (measured 4e-3), over a 60 mm shape.
  EXPECT_LT(result.rms_mm, 0.05);
  EXPECT_LT(max_map_difference(result.map, truth, shape), 0.2);
  EXPECT_NEAR(result.scale, 1.08, 2e-3);          // 0.2 mm over a 60 mm shape
  EXPECT_EQ(result.pairs, shape.num_vertices());  // none trimmed at the end
  EXPECT_TRUE(result.anchor_residuals_mm.empty());
}

TEST(BoneRegistrationTest, StartIsPartOfTheReturnedMap) {
  const mesh::IndexedMesh shape = asymmetric_shape();
  // The target lies far away, 90 degrees off: only the start brings the
  // source near it, and the result must still map the raw source.
  const Eigen::Affine3d truth =
      similarity(1.0, 90 * kDegree, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(500, -300, 800));
  const Eigen::Affine3d start =
      similarity(1.0, 87 * kDegree, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(502, -301, 799));
  const mesh::AabbTree target(mapped(shape, truth));
  RegistrationOptions options;
  options.anisotropic = false;
  const RegistrationResult result = register_points(shape.V, &target, {}, start, options);
  // As above: converged to the exact answer up to ICP's slow tail.
  EXPECT_LT(result.rms_mm, 0.05);
  EXPECT_LT(max_map_difference(result.map, truth, shape), 0.2);
}

TEST(BoneRegistrationTest, AnisotropicStepRecoversAPerAxisStretch) {
  const mesh::IndexedMesh shape = asymmetric_shape();
  Eigen::Affine3d truth =
      similarity(1.0, 5 * kDegree, Eigen::Vector3d(0, 1, 1), Eigen::Vector3d(2, 1, -3));
  truth.linear() = truth.linear() * Eigen::Vector3d(1.10, 0.95, 1.05).asDiagonal();
  const mesh::AabbTree target(mapped(shape, truth));

  RegistrationOptions similarity_only;
  similarity_only.anisotropic = false;
  const RegistrationResult rigid =
      register_points(shape.V, &target, {}, Eigen::Affine3d::Identity(), similarity_only);

  // Nearly unregularised: the affine map is free to take the stretch.
  RegistrationOptions free_affine;
  free_affine.affine_regularisation = 1e-6;
  free_affine.affine_iterations = 100;
  const RegistrationResult affine =
      register_points(shape.V, &target, {}, Eigen::Affine3d::Identity(), free_affine);
  // A similarity cannot follow a 10 % / 5 % stretch: it leaves 0.7 mm (measured).
  EXPECT_GT(rigid.rms_mm, 0.2);
  // The affine map can, exactly: ICP's tail again (measured 3e-3 mm).
  EXPECT_LT(affine.rms_mm, 0.1);
  EXPECT_LT(max_map_difference(affine.map, truth, shape), 0.5);
  // The per-axis scales come back (column norms of A = the stretch, since
  // the rotation keeps lengths) to 1 %, 0.3 mm over 30 mm.
  const Eigen::Vector3d stretch = affine.map.linear().colwise().norm().transpose();
  EXPECT_NEAR(stretch.x(), 1.10, 0.01);
  EXPECT_NEAR(stretch.y(), 0.95, 0.01);
  EXPECT_NEAR(stretch.z(), 1.05, 0.01);

  // The default regularisation pulls the map towards the similarity: it ends
  // between the two, closer than the similarity alone (measured 0.25 mm).
  const RegistrationResult regularised =
      register_points(shape.V, &target, {}, Eigen::Affine3d::Identity(), {});
  EXPECT_LT(regularised.rms_mm, rigid.rms_mm);
  EXPECT_GE(regularised.rms_mm, affine.rms_mm);
}

TEST(BoneRegistrationTest, KeepScaleKeepsTheStartScale) {
  const mesh::IndexedMesh shape = asymmetric_shape();
  // The target is the shape grown by 10 % about its centre and moved.
  const Eigen::Affine3d truth =
      similarity(1.10, 6 * kDegree, Eigen::Vector3d(1, 0, 1), Eigen::Vector3d(1, 2, 3));
  const mesh::AabbTree target(mapped(shape, truth));
  RegistrationOptions options;
  options.anisotropic = false;
  options.keep_scale = true;
  // From a start at scale 1.2, rigid steps keep 1.2 exactly.
  Eigen::Affine3d start = Eigen::Affine3d::Identity();
  start.linear() *= 1.2;
  const RegistrationResult kept = register_points(shape.V, &target, {}, start, options);
  EXPECT_NEAR(kept.scale, 1.2, 1e-9);  // rotations have det 1, up to rounding
  // From the true scale, rigid steps find the rest of the map.
  start.linear() = 1.10 * Eigen::Matrix3d::Identity();
  const RegistrationResult right = register_points(shape.V, &target, {}, start, options);
  EXPECT_NEAR(right.scale, 1.10, 1e-9);
  EXPECT_LT(right.rms_mm, 0.05);  // converged, as in the similarity test
  // Without keep_scale the similarity steps move the scale from 1.2 to 1.1.
  options.keep_scale = false;
  start.linear() = 1.2 * Eigen::Matrix3d::Identity();
  const RegistrationResult free = register_points(shape.V, &target, {}, start, options);
  EXPECT_NEAR(free.scale, 1.10, 2e-3);  // 0.1 mm over the shape, as above
}

TEST(BoneRegistrationTest, AnchorsAloneGiveTheirSimilarity) {
  const Eigen::Affine3d truth =
      similarity(1.3, 35 * kDegree, Eigen::Vector3d(1, -1, 2), Eigen::Vector3d(100, 20, -40));
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {40, 0, 0}, {0, 25, 0}, {5, 5, 30}};
  std::vector<RegistrationAnchor> anchors;
  for (std::size_t i = 0; i < points.size(); ++i) {
    anchors.push_back({"a" + std::to_string(i), points[i], truth * points[i], 1.0});
  }
  const Eigen::MatrixX3d none(0, 3);
  for (const bool anisotropic : {false, true}) {
    RegistrationOptions options;
    options.anisotropic = anisotropic;
    const RegistrationResult result =
        register_points(none, nullptr, anchors, Eigen::Affine3d::Identity(), options);
    // Exact pairs of a similarity: the closed-form fit is exact up to
    // rounding (1e-9 of the 100 mm coordinates); the affine step's prior is
    // that same similarity, so it stays.
    EXPECT_LT((result.map.linear() - truth.linear()).norm(), 1e-9) << anisotropic;
    EXPECT_LT((result.map.translation() - truth.translation()).norm(), 1e-7) << anisotropic;
    EXPECT_NEAR(result.scale, 1.3, 1e-9);
    EXPECT_EQ(result.pairs, 0);
    EXPECT_EQ(result.rms_mm, 0.0);
    ASSERT_EQ(result.anchor_residuals_mm.size(), 4U);
    EXPECT_EQ(result.anchor_residuals_mm[2].first, "a2");
    for (const auto& [name, residual] : result.anchor_residuals_mm) {
      EXPECT_LT(residual, 1e-7) << name;
    }
  }
  // Three anchors still determine a similarity.
  anchors.pop_back();
  RegistrationOptions options;
  options.anisotropic = false;
  const RegistrationResult three =
      register_points(none, nullptr, anchors, Eigen::Affine3d::Identity(), options);
  EXPECT_LT((three.map.linear() - truth.linear()).norm(), 1e-9);
}

TEST(BoneRegistrationTest, TooFewOrCollinearAnchorsThrow) {
  const Eigen::MatrixX3d none(0, 3);
  std::vector<RegistrationAnchor> two = {{"a", {0, 0, 0}, {1, 0, 0}, 1.0},
                                         {"b", {10, 0, 0}, {11, 0, 0}, 1.0}};
  EXPECT_THROW((void)register_points(none, nullptr, two, Eigen::Affine3d::Identity()),
               InvalidInputError);
  std::vector<RegistrationAnchor> collinear = two;
  collinear.push_back({"c", {20, 0, 0}, {21, 0, 0}, 1.0});
  EXPECT_THROW((void)register_points(none, nullptr, collinear, Eigen::Affine3d::Identity()),
               InvalidInputError);
}

TEST(BoneRegistrationTest, AnchorPullsASymmetricSurfaceFitIntoPlace) {
  // A sphere fits itself under any rotation: the surface alone leaves the
  // rotation free; an anchor off the centre fixes it.
  const mesh::IndexedMesh sphere = mesh::make_icosphere(3, 20.0);
  const Eigen::Affine3d truth =
      similarity(1.0, 20 * kDegree, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, 2, 0));
  const mesh::AabbTree target(mapped(sphere, truth));
  const Eigen::Vector3d marker(0, 0, 0);
  const Eigen::Vector3d pole(20, 0, 0);
  std::vector<RegistrationAnchor> anchors = {
      {"centre", marker, truth * marker, 1.0},
      {"pole", pole, truth * pole, 1.0},
      {"top", Eigen::Vector3d(0, 0, 20), truth * Eigen::Vector3d(0, 0, 20), 1.0}};
  RegistrationOptions options;
  options.anisotropic = false;
  const RegistrationResult result =
      register_points(sphere.V, &target, anchors, Eigen::Affine3d::Identity(), options);
  // Anchors as heavy as the surface pull the pole onto its place: within a
  // tenth of a mm (the faceted sphere's surface pairs disagree with the
  // exact anchors by at most the ~0.1 mm gap of an inscribed icosphere).
  for (const auto& [name, residual] : result.anchor_residuals_mm) {
    EXPECT_LT(residual, 0.1) << name;
  }
  EXPECT_LT((result.map * pole - truth * pole).norm(), 0.1);
}

TEST(BoneRegistrationTest, NearestRotationOfScaledAndStretchedRotations) {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  // Exact up to rounding of the SVD.
  EXPECT_LT((nearest_rotation(1000.0 * rotation) - rotation).norm(), 1e-12);
  EXPECT_LT((nearest_rotation(0.01 * rotation) - rotation).norm(), 1e-12);
  // R times a symmetric positive stretch: R is the polar factor.
  const Eigen::Matrix3d stretched = rotation * Eigen::Vector3d(1.2, 0.9, 1.1).asDiagonal();
  EXPECT_LT((nearest_rotation(stretched) - rotation).norm(), 1e-12);
  // A reflection has no rotation polar factor: still a proper rotation.
  const Eigen::Matrix3d mirrored = rotation * Eigen::Vector3d(1, 1, -1).asDiagonal();
  const Eigen::Matrix3d proper = nearest_rotation(mirrored);
  EXPECT_NEAR(proper.determinant(), 1.0, 1e-12);
  EXPECT_LT((proper.transpose() * proper - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(BoneRegistrationTest, NonFiniteInputIsRejected) {
  const mesh::IndexedMesh shape = asymmetric_shape();
  const mesh::AabbTree target(shape);
  Eigen::MatrixX3d source = shape.V;
  source(5, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)register_points(source, &target, {}, Eigen::Affine3d::Identity()),
               InvalidInputError);
  const std::vector<RegistrationAnchor> infinite = {
      {"bad", Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 0), {0, 0, 0}, 1.0}};
  EXPECT_THROW((void)register_points(shape.V, &target, infinite, Eigen::Affine3d::Identity()),
               InvalidInputError);
  const std::vector<RegistrationAnchor> bad_target = {
      {"bad", {0, 0, 0}, Eigen::Vector3d(0, std::numeric_limits<double>::quiet_NaN(), 0), 1.0}};
  EXPECT_THROW((void)register_points(shape.V, &target, bad_target, Eigen::Affine3d::Identity()),
               InvalidInputError);
  const std::vector<RegistrationAnchor> negative = {{"bad", {0, 0, 0}, {0, 0, 0}, -1.0}};
  EXPECT_THROW((void)register_points(shape.V, &target, negative, Eigen::Affine3d::Identity()),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::atlas

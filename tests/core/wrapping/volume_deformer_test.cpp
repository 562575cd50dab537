// The volume-preserving deformer on analytic cases: a rigid motion is
// reproduced exactly, an inflating or stretching skeleton changes the shape
// but not the volume (to the tolerance), and a sphere driven into a
// half-space "bone" comes out of it with its volume intact.

#include "core/wrapping/volume_deformer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::wrapping {
namespace {

using Eigen::MatrixX3d;
using Eigen::Vector3d;

constexpr double kDeformerSphereRadius = 20.0;

mesh::IndexedMesh sphere() { return mesh::make_icosphere(4, kDeformerSphereRadius); }

TEST(VolumeDeformerTest, TheRestTargetsGiveTheRestSurface) {
  const mesh::IndexedMesh rest = sphere();
  const VolumeDeformer deformer(rest);
  const DeformResult result = deformer.solve(rest.V, {});
  EXPECT_LT((result.x - rest.V).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LT(std::abs(result.volume_error), 1e-11);
  EXPECT_TRUE(result.converged);
}

TEST(VolumeDeformerTest, ARigidMotionOfTheSkeletonMovesTheSurfaceRigidly) {
  const mesh::IndexedMesh rest = sphere();
  const VolumeDeformer deformer(rest);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Vector3d t(15, -40, 8);
  const MatrixX3d targets = (rest.V * R.transpose()).rowwise() + t.transpose();
  const std::vector<Eigen::Matrix3d> rotations(static_cast<std::size_t>(rest.V.rows()), R);
  const DeformResult result = deformer.solve(targets, rotations);
  EXPECT_LT((result.x - targets).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT(std::abs(result.volume_error), 1e-9);
}

TEST(VolumeDeformerTest, AnInflatingSkeletonKeepsTheVolumeAndTheSphere) {
  // Targets 20 % larger: 1.728 times the volume. The hard constraint holds
  // the volume; by symmetry the answer is the rest sphere again.
  const mesh::IndexedMesh rest = sphere();
  const VolumeDeformer deformer(rest);
  const DeformResult result = deformer.solve(1.2 * rest.V, {});
  EXPECT_TRUE(result.converged);
  EXPECT_LT(std::abs(result.volume_error), 1e-9);
  EXPECT_GE(result.volume_iterations, 1);
  const Eigen::VectorXd radii = result.x.rowwise().norm();
  EXPECT_LT((radii.array() - kDeformerSphereRadius).abs().maxCoeff(), 0.01 * kDeformerSphereRadius);
}

TEST(VolumeDeformerTest, AStretchedSkeletonThinsTheSurfaceAtConstantVolume) {
  // Targets stretched 1.5 times along z: the analytic volume of the targets
  // is 1.5 times the rest volume; the solution keeps the rest volume, so it
  // must be longer than the sphere and thinner than the targets.
  const mesh::IndexedMesh rest = sphere();
  const VolumeDeformer deformer(rest);
  MatrixX3d targets = rest.V;
  targets.col(2) *= 1.5;
  ASSERT_NEAR(enclosed_volume(targets, rest.F) / deformer.rest_volume(), 1.5, 1e-9);
  const DeformResult result = deformer.solve(targets, {});
  EXPECT_LT(std::abs(result.volume_error), 1e-9);
  const double height = result.x.col(2).maxCoeff() - result.x.col(2).minCoeff();
  const double width = result.x.col(0).maxCoeff() - result.x.col(0).minCoeff();
  EXPECT_GT(height, 2.2 * kDeformerSphereRadius);
  EXPECT_LT(width, 2.0 * kDeformerSphereRadius * 0.97);
  // The volume of an ellipsoid with these extents is close to the rest volume.
  const double ellipsoid = 4.0 / 3.0 * std::numbers::pi * (width / 2) * (width / 2) * (height / 2);
  EXPECT_NEAR(ellipsoid / deformer.rest_volume(), 1.0, 0.05);
}

TEST(VolumeDeformerTest, TheVolumeGradientMatchesFiniteDifferences) {
  const mesh::IndexedMesh rest = mesh::make_icosphere(1, 3.0);
  const MatrixX3d gradient = enclosed_volume_gradient(rest.V, rest.F);
  for (int vertex : {0, 5, 11}) {
    for (int axis = 0; axis < 3; ++axis) {
      MatrixX3d plus = rest.V;
      MatrixX3d minus = rest.V;
      plus(vertex, axis) += 1e-6;
      minus(vertex, axis) -= 1e-6;
      const double numeric =
          (enclosed_volume(plus, rest.F) - enclosed_volume(minus, rest.F)) / 2e-6;
      EXPECT_NEAR(gradient(vertex, axis), numeric, 1e-6);
    }
  }
}

// The bone is the half-space z < 0: a vertex deeper than 0.05 mm becomes a
// contact pinned 0.1 mm above the plane, where it was in x and y.
std::vector<Contact> half_space_contacts(const MatrixX3d& x, const std::vector<char>& active) {
  std::vector<Contact> found;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    if (active[static_cast<std::size_t>(i)] == 0 && x(i, 2) < -0.05) {
      found.push_back({static_cast<int>(i), Vector3d(x(i, 0), x(i, 1), 0.1)});
    }
  }
  return found;
}

TEST(VolumeDeformerTest, AMuscleForcedIntoABoneComesOutOfItWithItsVolume) {
  // The skeleton carries the sphere 8 mm into the bone (its lowest point at
  // z = -8): contacts push the entered cap out, the volume moves up.
  const mesh::IndexedMesh rest = sphere();
  const VolumeDeformer deformer(rest);
  const MatrixX3d targets =
      rest.V.rowwise() + Eigen::RowVector3d(0, 0, kDeformerSphereRadius - 8.0);
  ASSERT_LT(targets.col(2).minCoeff(), -7.9);
  const DeformResult result = deformer.solve(targets, {}, {}, half_space_contacts);
  EXPECT_TRUE(result.converged);
  EXPECT_GE(result.contact_rounds, 1);
  EXPECT_GT(result.contacts.size(), 20U);
  EXPECT_GT(result.x.col(2).minCoeff(), -0.06);  // no vertex left inside
  EXPECT_LT(std::abs(result.volume_error), 1e-9);
  // The displaced volume went sideways and up: wider and taller than the sphere.
  const double width = result.x.col(0).maxCoeff() - result.x.col(0).minCoeff();
  EXPECT_GT(width, 2.0 * kDeformerSphereRadius + 1.0);
  EXPECT_GT(result.x.col(2).maxCoeff(), targets.col(2).maxCoeff());
  std::printf("contacts %zu rounds %d iterations %d width %.2f top +%.2f\n", result.contacts.size(),
              result.contact_rounds, result.volume_iterations, width,
              result.x.col(2).maxCoeff() - targets.col(2).maxCoeff());
}

TEST(VolumeDeformerTest, StartingContactsArePinnedFromTheFirstSolve) {
  const mesh::IndexedMesh rest = sphere();
  const VolumeDeformer deformer(rest);
  const Vector3d pinned = rest.V.row(0).transpose() + Vector3d(0, 0, 2.0);
  const DeformResult result = deformer.solve(rest.V, {}, {{0, pinned}});
  EXPECT_LT((result.x.row(0).transpose() - pinned).norm(), 0.05);
  EXPECT_LT(std::abs(result.volume_error), 1e-9);
}

TEST(VolumeDeformerTest, AContactsOwnWeightHoldsItMoreOrLessFirmly) {
  const mesh::IndexedMesh rest = sphere();
  const VolumeDeformer deformer(rest);
  const Vector3d pinned = rest.V.row(0).transpose() + Vector3d(0, 0, 4.0);
  const auto reached = [&](double weight) {
    const DeformResult result = deformer.solve(rest.V, {}, {{0, pinned, -1, weight}});
    EXPECT_LT(std::abs(result.volume_error), 1e-9);
    return 1.0 - (result.x.row(0).transpose() - pinned).norm() / 4.0;
  };
  const double by_default = reached(0.0);  // DeformerOptions::contact_weight
  EXPECT_GT(by_default, 0.98);
  EXPECT_DOUBLE_EQ(reached(DeformerOptions{}.contact_weight), by_default);
  const double soft = reached(1e-3);
  EXPECT_LT(soft, 0.5 * by_default);
  EXPECT_GT(soft, 0.0);
  EXPECT_LT(soft, reached(1.0));
  EXPECT_THROW((void)deformer.solve(rest.V, {}, {{0, pinned, -1, -1.0}}), InvalidInputError);
}

TEST(VolumeDeformerTest, BadInputIsRefusedWithTheReason) {
  const mesh::IndexedMesh rest = sphere();
  mesh::IndexedMesh inward = rest;
  inward.F.col(1).swap(inward.F.col(2));
  EXPECT_THROW(VolumeDeformer{inward}, InvalidInputError);
  DeformerOptions options;
  options.stiffness_length_mm = 0;
  EXPECT_THROW(VolumeDeformer(rest, options), InvalidInputError);
  const VolumeDeformer deformer(rest);
  EXPECT_THROW((void)deformer.solve(rest.V.topRows(10), {}), InvalidInputError);
  MatrixX3d nan = rest.V;
  nan(3, 1) = std::nan("");
  EXPECT_THROW((void)deformer.solve(nan, {}), InvalidInputError);
  EXPECT_THROW((void)deformer.solve(rest.V, {}, {{-1, Vector3d::Zero()}}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping

// Bone contacts: the culled query finds exactly the vertices a brute-force
// signed distance finds, and a muscle forced into a bone (by its skeleton,
// or by the bone moving into it) comes out with its volume intact.

#include "core/wrapping/bone_contacts.h"

#include <gtest/gtest.h>

#include <random>

#include "core/mesh/primitives.h"
#include "core/wrapping/volume_deformer.h"

namespace mmm::wrapping {
namespace {

using Eigen::Isometry3d;
using Eigen::MatrixX3d;
using Eigen::Vector3d;

// A 40 mm cube "bone" under a sphere "muscle" of radius 15 resting on it.
std::vector<PosableBone> cube_bone() {
  const mesh::IndexedMesh cube = mesh::make_box(Vector3d(-20, -20, -40), Vector3d(20, 20, 0));
  return {{"cube", std::make_shared<const mesh::SignedDistance>(cube)}};
}

mesh::IndexedMesh resting_sphere() {
  mesh::IndexedMesh sphere = mesh::make_icosphere(4, 15.0);
  sphere.V.col(2).array() += 15.0;
  return sphere;
}

TEST(BoneContactsTest, TheCulledQueryFindsWhatBruteForceFinds) {
  const mesh::IndexedMesh sphere = resting_sphere();
  const std::vector<PosableBone> bones = cube_bone();
  const BoneContacts contacts(sphere.V, bones, {.tolerance_mm = 0.0, .clearance_mm = 0.0});
  std::mt19937 random(7);
  std::normal_distribution<double> jitter(0.0, 3.0);
  for (int trial = 0; trial < 5; ++trial) {
    MatrixX3d x = sphere.V;
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      x.row(i) += Eigen::RowVector3d(jitter(random), jitter(random), jitter(random) - 2.0);
    Isometry3d pose = Isometry3d::Identity();
    pose.translation() = Vector3d(jitter(random), jitter(random), jitter(random));
    const std::vector<Contact> found =
        contacts.find(x, {pose}, std::vector<char>(static_cast<std::size_t>(x.rows()), 0));
    std::vector<int> expected;
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      if (bones[0].surface->at(pose.inverse() * Vector3d(x.row(i).transpose())) < 0)
        expected.push_back(static_cast<int>(i));
    }
    std::vector<int> got;
    got.reserve(found.size());
    for (const Contact& c : found) got.push_back(c.vertex);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << "trial " << trial;
    EXPECT_GT(expected.size(), 10U);
  }
}

TEST(BoneContactsTest, AMuscleForcedIntoABoneComesOutOfItWithItsVolume) {
  const mesh::IndexedMesh sphere = resting_sphere();
  const BoneContacts contacts(sphere.V, cube_bone(), {.tolerance_mm = 0.1, .clearance_mm = 0.0});
  const VolumeDeformer deformer(sphere);
  // The skeleton carries the sphere 6 mm down into the cube.
  const MatrixX3d targets = sphere.V.rowwise() - Eigen::RowVector3d(0, 0, 6.0);
  const std::vector<Isometry3d> poses{Isometry3d::Identity()};
  ASSERT_GT(contacts.measure(targets, poses).max_depth_mm, 5.9);
  const DeformResult result =
      deformer.solve(targets, {}, {}, [&](const MatrixX3d& x, const std::vector<char>& active) {
        return contacts.find(x, poses, active);
      });
  const PenetrationMetrics after = contacts.measure(result.x, poses);
  EXPECT_LE(after.max_depth_mm, 0.1 + 1e-9);
  EXPECT_EQ(after.vertices_deeper, 0);
  EXPECT_LT(std::abs(result.volume_error), 1e-9);
  EXPECT_GT(result.contacts.size(), 50U);
}

TEST(BoneContactsTest, ABoneMovingIntoTheMuscleIsSeenThroughItsPose) {
  const mesh::IndexedMesh sphere = resting_sphere();
  const BoneContacts contacts(sphere.V, cube_bone(), {.tolerance_mm = 0.1, .clearance_mm = 0.0});
  Isometry3d up = Isometry3d::Identity();
  up.translation() = Vector3d(0, 0, 5.0);
  EXPECT_EQ(contacts.measure(sphere.V, {Isometry3d::Identity()}).vertices_deeper, 0);
  const PenetrationMetrics moved = contacts.measure(sphere.V, {up});
  EXPECT_NEAR(moved.max_depth_mm, 5.0, 0.05);
  EXPECT_EQ(moved.deepest_bone, "cube");
  const VolumeDeformer deformer(sphere);
  const DeformResult result =
      deformer.solve(sphere.V, {}, {}, [&](const MatrixX3d& x, const std::vector<char>& active) {
        return contacts.find(x, {up}, active);
      });
  EXPECT_LE(contacts.measure(result.x, {up}).max_depth_mm, 0.1 + 1e-9);
  EXPECT_LT(std::abs(result.volume_error), 1e-9);
}

}  // namespace
}  // namespace mmm::wrapping

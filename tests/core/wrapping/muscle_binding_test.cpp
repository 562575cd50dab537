// Binding a muscle to its action lines and attachment bones: the rest pose
// gives the rest surface, a rigid motion of everything moves it rigidly, a
// stretched line stretches the muscle along it.

#include "core/wrapping/muscle_binding.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::wrapping {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

// A spindle along z from 0 to 100 mm and its straight action line; pose 0
// is the origin bone, pose 1 the insertion bone.
struct Spindle {
  mesh::IndexedMesh mesh;
  LinePath line;
};

Spindle spindle() {
  Spindle s;
  s.mesh = mesh::make_icosphere(3, 1.0);
  s.mesh.V.col(0) *= 12.0;
  s.mesh.V.col(1) *= 8.0;
  s.mesh.V.col(2) = (s.mesh.V.col(2).array() + 1.0) * 50.0;
  s.line.points = {Vector3d(0, 0, -5), Vector3d(0, 0, 50), Vector3d(0, 0, 105)};
  s.line.origin_pose_index = 0;
  s.line.insertion_pose_index = 1;
  return s;
}

TEST(MuscleBindingTest, TheRestPoseGivesTheRestSurface) {
  const Spindle s = spindle();
  const MuscleBinding binding(s.mesh.V, s.mesh.F, {s.line}, {});
  const auto targets = binding.targets({s.line}, {Isometry3d::Identity(), Isometry3d::Identity()});
  EXPECT_LT((targets.positions - s.mesh.V).cwiseAbs().maxCoeff(), 1e-9);
  for (const Eigen::Matrix3d& r : targets.rotations) EXPECT_TRUE(r.isIdentity(1e-9));
}

TEST(MuscleBindingTest, ARigidMotionOfEverythingMovesTheSurfaceRigidly) {
  const Spindle s = spindle();
  // Attached at the origin end to bone 0, so both kinds of target are used.
  AttachmentBone origin_bone{0, (s.mesh.V.col(2).array() - 0.0).abs().matrix()};
  const MuscleBinding binding(s.mesh.V, s.mesh.F, {s.line}, {origin_bone});
  Isometry3d T = Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.9, Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  T.translation() = Vector3d(300, -20, 40);
  LinePath moved = s.line;
  for (Vector3d& p : moved.points) p = T * p;
  const auto targets = binding.targets({moved}, {T, T});
  const Eigen::MatrixX3d expected =
      (s.mesh.V * T.linear().transpose()).rowwise() + T.translation().transpose();
  EXPECT_LT((targets.positions - expected).cwiseAbs().maxCoeff(), 1e-8);
  for (const Eigen::Matrix3d& r : targets.rotations) EXPECT_TRUE(r.isApprox(T.linear(), 1e-9));
}

TEST(MuscleBindingTest, AStretchedLineStretchesTheMuscleAlongIt) {
  const Spindle s = spindle();
  const MuscleBinding binding(s.mesh.V, s.mesh.F, {s.line}, {});
  LinePath stretched = s.line;
  for (Vector3d& p : stretched.points) p.z() = -5.0 + 1.2 * (p.z() + 5.0);
  const auto targets =
      binding.targets({stretched}, {Isometry3d::Identity(), Isometry3d::Identity()});
  // Along the line: z' = -5 + 1.2 (z + 5); across it nothing changes.
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i) {
    EXPECT_NEAR(targets.positions(i, 2), -5.0 + 1.2 * (s.mesh.V(i, 2) + 5.0), 1e-9);
    EXPECT_NEAR(targets.positions(i, 0), s.mesh.V(i, 0), 1e-9);
  }
}

TEST(MuscleBindingTest, BadLinesAndIndicesAreRefused) {
  const Spindle s = spindle();
  LinePath short_line = s.line;
  short_line.points.resize(1);
  EXPECT_THROW(MuscleBinding(s.mesh.V, s.mesh.F, {short_line}, {}), InvalidInputError);
  EXPECT_THROW(MuscleBinding(s.mesh.V, s.mesh.F, {}, {}), InvalidInputError);
  EXPECT_THROW(
      MuscleBinding(s.mesh.V, s.mesh.F, {s.line}, {AttachmentBone{0, Eigen::VectorXd::Zero(3)}}),
      InvalidInputError);
  const MuscleBinding binding(s.mesh.V, s.mesh.F, {s.line}, {});
  EXPECT_THROW((void)binding.targets({s.line}, {Isometry3d::Identity()}), InvalidInputError);
  EXPECT_THROW(
      (void)binding.targets({s.line, s.line}, {Isometry3d::Identity(), Isometry3d::Identity()}),
      InvalidInputError);
}

}  // namespace
}  // namespace mmm::wrapping

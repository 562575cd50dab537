// How cartilages and ligaments follow their bones: a cartilage exactly by its
// bone's rigid map; a ligament between two boxes by the smooth blend of the
// two maps, exact at each attachment and halfway in the middle.

#include "core/atlas/structure_carriage.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::atlas {
namespace {

Eigen::Isometry3d turn_and_shift(double angle, const Eigen::Vector3d& axis,
                                 const Eigen::Vector3d& shift) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  pose.translation() = shift;
  return pose;
}

TEST(StructureCarriageTest, ACartilageMovesRigidlyWithItsBone) {
  Structure cartilage;
  cartilage.name = "c";
  cartilage.bones = {"femur"};
  const mesh::IndexedMesh bone = mesh::make_box({-10, -10, 0}, {10, 10, 40});
  const mesh::SignedDistance bone_distance(bone);
  const mesh::IndexedMesh surface = mesh::make_icosphere(2, 5.0, {0, 0, -2});
  const Eigen::MatrixXd weights = carriage_weights(cartilage, surface.V, {&bone_distance});
  ASSERT_EQ(weights.cols(), 1);
  EXPECT_TRUE((weights.array() == 1.0).all());
  const Eigen::Isometry3d pose = turn_and_shift(0.7, {1, 2, 3}, {5, -4, 30});
  const Eigen::MatrixX3d moved = carried(surface.V, weights, {pose});
  for (Eigen::Index i = 0; i < surface.V.rows(); ++i) {
    EXPECT_LT(
        (moved.row(i).transpose() - pose * Eigen::Vector3d(surface.V.row(i).transpose())).norm(),
        1e-12);
  }
}

TEST(StructureCarriageTest, ALigamentBlendsItsTwoBonesSmoothlyAlongItsLength) {
  Structure ligament;
  ligament.name = "l";
  ligament.kind = StructureKind::kLigament;
  ligament.bones = {"femur", "tibia"};
  // Femur above z = 0, tibia below z = -20; the ligament spans the gap.
  const mesh::SignedDistance femur(mesh::make_box({-10, -10, 0}, {10, 10, 100}));
  const mesh::SignedDistance tibia(mesh::make_box({-10, -10, -120}, {10, 10, -20}));
  Eigen::MatrixX3d points(4, 3);
  points << 0, 0, 0,  // on the femur
      0, 0, -20,      // on the tibia
      0, 0, -10,      // halfway
      0, 0, -5;       // a quarter of the way
  const Eigen::MatrixXd weights = carriage_weights(ligament, points, {&femur, &tibia});
  EXPECT_NEAR(weights(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(weights(1, 1), 1.0, 1e-12);
  EXPECT_NEAR(weights(2, 1), 0.5, 1e-12);
  EXPECT_NEAR(weights(3, 1), 3 * 0.0625 - 2 * 0.015625, 1e-12);  // 3t^2 - 2t^3 at t = 1/4
  EXPECT_TRUE(weights.rowwise().sum().isApprox(Eigen::VectorXd::Ones(4), 1e-12));
  // The tibia drops 8 mm: its attachment follows it fully, the middle half.
  const Eigen::MatrixX3d moved = carried(
      points, weights, {Eigen::Isometry3d::Identity(), turn_and_shift(0.0, {1, 0, 0}, {0, 0, -8})});
  EXPECT_NEAR(moved(0, 2), 0.0, 1e-12);
  EXPECT_NEAR(moved(1, 2), -28.0, 1e-12);
  EXPECT_NEAR(moved(2, 2), -14.0, 1e-12);
}

TEST(StructureCarriageTest, MismatchedBonesOrPosesAreRejected) {
  Structure ligament;
  ligament.name = "l";
  ligament.kind = StructureKind::kLigament;
  ligament.bones = {"femur", "tibia"};
  const mesh::SignedDistance femur(mesh::make_box({-10, -10, 0}, {10, 10, 100}));
  const Eigen::MatrixX3d points = Eigen::MatrixX3d::Zero(2, 3);
  EXPECT_THROW((void)carriage_weights(ligament, points, {&femur}), InvalidInputError);
  EXPECT_THROW((void)carried(points, Eigen::MatrixXd::Ones(2, 2), {Eigen::Isometry3d::Identity()}),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::atlas

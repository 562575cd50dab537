// Targets blended across the interfaces of touching muscles: two spheres
// that touch at a point, driven apart by their own targets, get the same
// target where they touch, each keeps its own far from the other, a rigid
// motion of the neighbour is carried exactly, attachments keep their own
// motion, and a bad reach is refused.

#include "core/wrapping/muscle_interfaces.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::wrapping {
namespace {

constexpr double kInterfaceSphereRadius = 10.0;
constexpr double kReach = 5.0;

mesh::IndexedMesh interface_sphere_at(const Eigen::Vector3d& centre) {
  mesh::IndexedMesh sphere = mesh::make_icosphere(3, kInterfaceSphereRadius);
  sphere.V.rowwise() += centre.transpose();
  return sphere;
}

// Every vertex moved by `motion` (rotations: its linear part).
MuscleBinding::Targets moved(const mesh::IndexedMesh& surface, const Eigen::Isometry3d& motion) {
  MuscleBinding::Targets targets;
  targets.positions.resize(surface.V.rows(), 3);
  for (Eigen::Index v = 0; v < surface.V.rows(); ++v)
    targets.positions.row(v) = (motion * Eigen::Vector3d(surface.V.row(v).transpose())).transpose();
  targets.rotations.assign(static_cast<std::size_t>(surface.V.rows()), motion.linear());
  return targets;
}

Eigen::Index extreme_vertex(const mesh::IndexedMesh& surface, double direction) {
  Eigen::Index v = 0;
  (direction * surface.V.col(0)).maxCoeff(&v);
  return v;
}

class MuscleInterfacesTest : public ::testing::Test {
 protected:
  // A at the origin, B touching it at (10, 0, 0).
  mesh::IndexedMesh a = interface_sphere_at({0, 0, 0});
  mesh::IndexedMesh b = interface_sphere_at({2 * kInterfaceSphereRadius, 0, 0});
  MuscleSurfaces rest{{a.V, b.V}, {&a.F, &b.F}, 2};
  std::vector<std::vector<InterfaceLink>> links = muscle_interfaces(rest, kReach, 2);
};

TEST_F(MuscleInterfacesTest, LinksOnlyVerticesWithinReachOfTheOtherMuscle) {
  ASSERT_EQ(links.size(), 2U);
  ASSERT_FALSE(links[0].empty());
  ASSERT_FALSE(links[1].empty());
  for (std::size_t m = 0; m < 2; ++m) {
    const mesh::IndexedMesh& own = m == 0 ? a : b;
    const mesh::IndexedMesh& other = m == 0 ? b : a;
    for (const InterfaceLink& link : links[m]) {
      EXPECT_EQ(link.muscle, 1 - static_cast<int>(m));
      const Eigen::Vector3d p = own.V.row(link.vertex).transpose();
      const double distance = rest.surface(1 - m).at(p);
      EXPECT_LT(distance, kReach);
      EXPECT_GT(link.weight, 0.0);
      EXPECT_LE(link.weight, 0.5);
      EXPECT_NEAR(link.weight, 0.5 * std::pow(1.0 - distance / kReach, 2), 0.02);
      EXPECT_TRUE(link.offset.isApprox(p - other.V.row(link.other_vertex).transpose()));
    }
    // Every vertex within half the reach of the other sphere is linked.
    int near = 0;
    for (Eigen::Index v = 0; v < own.V.rows(); ++v)
      near += rest.surface(1 - m).at(Eigen::Vector3d(own.V.row(v).transpose())) < 0.5 * kReach;
    EXPECT_GE(static_cast<int>(links[m].size()), near);
  }
}

TEST_F(MuscleInterfacesTest, TouchingMusclesDrivenApartMeetWhereTheyTouch) {
  // A's targets slide 4 mm up, B's 4 mm down: along the contact they would shear.
  const MuscleBinding::Targets up = moved(a, Eigen::Isometry3d(Eigen::Translation3d(0, 4, 0)));
  const MuscleBinding::Targets down = moved(b, Eigen::Isometry3d(Eigen::Translation3d(0, -4, 0)));
  const std::vector<const MuscleBinding::Targets*> all = {&up, &down};
  const Eigen::VectorXd free_a = Eigen::VectorXd::Zero(a.V.rows());
  const Eigen::VectorXd free_b = Eigen::VectorXd::Zero(b.V.rows());
  const MuscleBinding::Targets blended_a = blend_interfaces(up, links[0], all, free_a);
  const MuscleBinding::Targets blended_b = blend_interfaces(down, links[1], all, free_b);
  // The touching tips (both at (10, 0, 0)) get the mean of the two motions: where they are.
  const Eigen::Index tip_a = extreme_vertex(a, 1.0);
  const Eigen::Index tip_b = extreme_vertex(b, -1.0);
  EXPECT_TRUE(blended_a.positions.row(tip_a).isApprox(a.V.row(tip_a), 1e-12));
  EXPECT_TRUE(blended_b.positions.row(tip_b).isApprox(b.V.row(tip_b), 1e-12));
  EXPECT_TRUE(blended_a.positions.row(tip_a).isApprox(blended_b.positions.row(tip_b), 1e-12));
  // The far sides keep their own targets exactly.
  const Eigen::Index back_a = extreme_vertex(a, -1.0);
  EXPECT_EQ(blended_a.positions.row(back_a), up.positions.row(back_a));
  // A linked vertex moves between its own motion and the other's, by its weight.
  for (const InterfaceLink& link : links[0]) {
    const double slide = blended_a.positions(link.vertex, 1) - a.V(link.vertex, 1);
    EXPECT_NEAR(slide, 4.0 * (1.0 - link.weight) - 4.0 * link.weight, 1e-9);
  }
}

TEST_F(MuscleInterfacesTest, ARigidMotionOfTheNeighbourIsCarriedExactly) {
  // B turns 30 degrees about z through its centre; A stays.
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.translate(Eigen::Vector3d(2 * kInterfaceSphereRadius, 0, 0));
  turn.rotate(Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()));
  turn.translate(Eigen::Vector3d(-2 * kInterfaceSphereRadius, 0, 0));
  const MuscleBinding::Targets still = moved(a, Eigen::Isometry3d::Identity());
  const MuscleBinding::Targets turned = moved(b, turn);
  const std::vector<const MuscleBinding::Targets*> all = {&still, &turned};
  const MuscleBinding::Targets blended =
      blend_interfaces(still, links[0], all, Eigen::VectorXd::Zero(a.V.rows()));
  for (const InterfaceLink& link : links[0]) {
    const Eigen::Vector3d p = a.V.row(link.vertex).transpose();
    const Eigen::Vector3d expected = (1.0 - link.weight) * p + link.weight * (turn * p);
    EXPECT_TRUE(blended.positions.row(link.vertex).transpose().isApprox(expected, 1e-9));
    const Eigen::AngleAxisd rotation(blended.rotations[static_cast<std::size_t>(link.vertex)]);
    EXPECT_NEAR(rotation.angle(), link.weight * M_PI / 6, 1e-9);
  }
}

TEST_F(MuscleInterfacesTest, AttachmentsKeepTheirOwnMotion) {
  const MuscleBinding::Targets up = moved(a, Eigen::Isometry3d(Eigen::Translation3d(0, 4, 0)));
  const MuscleBinding::Targets down = moved(b, Eigen::Isometry3d(Eigen::Translation3d(0, -4, 0)));
  const MuscleBinding::Targets blended =
      blend_interfaces(up, links[0], {&up, &down}, Eigen::VectorXd::Ones(a.V.rows()));
  EXPECT_EQ(blended.positions, up.positions);
}

TEST(MuscleInterfacesErrorsTest, ABadReachIsRefused) {
  const mesh::IndexedMesh a = interface_sphere_at({0, 0, 0});
  const MuscleSurfaces one({a.V}, {&a.F}, 1);
  EXPECT_THROW((void)muscle_interfaces(one, 0.0, 1), InvalidInputError);
  EXPECT_THROW((void)muscle_interfaces(one, std::nan(""), 1), InvalidInputError);
  EXPECT_TRUE(muscle_interfaces(one, 5.0, 1).front().empty());  // alone: nothing to blend
}

}  // namespace
}  // namespace mmm::wrapping

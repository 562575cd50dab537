// Touching surfaces solved together on analytic cases: two equal spheres
// carried into each other meet halfway with no vertex inside the other and
// their volumes exact; a disc pressed between two spheres (where rounds of
// one-sided pins chase each other) comes out with no vertex inside either;
// bodies that do not touch are left alone; pins hold; bad input is refused.

#include "core/wrapping/joint_deformer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "core/mesh/signed_distance.h"

namespace mmm::wrapping {
namespace {

using Eigen::MatrixX3d;
using Eigen::RowVector3d;
using Eigen::Vector3d;

constexpr double kJointSphereRadius = 20.0;
constexpr double kBone = 12.0;  // a half-space bone: y > kBone

// A body whose skeleton carries its rest surface to `targets` (no rotation),
// starting from its own volume-preserving solve, as a muscle does.
JointBody body(const VolumeDeformer& deformer, const MatrixX3d& targets) {
  JointBody b;
  b.deformer = &deformer;
  b.right_hand_side = deformer.right_hand_side(targets, {});
  b.start = deformer.solve(targets, {}).x;
  return b;
}

// Depth (mm, >= 0) of the deepest vertex of x inside the closed surface (y, F).
double deepest_inside(const MatrixX3d& x, const MatrixX3d& y, const Eigen::MatrixX3i& F) {
  const mesh::SignedDistance other(mesh::IndexedMesh{y, F});
  return std::max(0.0, -other.at(x).minCoeff());
}

JointOptions options() {
  JointOptions o;
  o.coupling.tolerance_mm = 0.05;
  return o;
}

TEST(JointDeformerTest, TwoSpheresCarriedIntoEachOtherMeetHalfwayKeepingTheirVolumes) {
  const mesh::IndexedMesh rest = mesh::make_icosphere(4, kJointSphereRadius);
  const VolumeDeformer deformer(rest);
  // Centres 36 mm apart: 4 mm of overlap along x.
  const MatrixX3d left = rest.V.rowwise() + RowVector3d(-18, 0, 0);
  const MatrixX3d right = rest.V.rowwise() + RowVector3d(18, 0, 0);
  const std::vector<JointBody> bodies = {body(deformer, left), body(deformer, right)};
  ASSERT_GT(deepest_inside(bodies[0].start, bodies[1].start, rest.F), 3.5);

  const JointResult result = solve_jointly(bodies, options());
  ASSERT_EQ(result.bodies.size(), 2U);
  EXPECT_TRUE(result.converged);
  EXPECT_GE(result.rounds, 1);
  EXPECT_EQ(result.largest_group, 2);
  EXPECT_GT(result.couplings[0], 0);
  EXPECT_GT(result.couplings[1], 0);
  const MatrixX3d& a = result.bodies[0].x;
  const MatrixX3d& b = result.bodies[1].x;
  EXPECT_LE(deepest_inside(a, b, rest.F), 0.05);
  EXPECT_LE(deepest_inside(b, a, rest.F), 0.05);
  for (const DeformResult& r : result.bodies) {
    EXPECT_LT(std::abs(r.volume_error), 1e-9);
    EXPECT_TRUE(r.converged);
  }
  // Mirror images: each gave way as far as the other, to the plane x = 0.
  const double reach_a = a.col(0).maxCoeff();
  const double reach_b = b.col(0).minCoeff();
  EXPECT_NEAR(reach_a, -reach_b, 0.05);
  EXPECT_NEAR(reach_a, 0.0, 0.2);
  // Each was pushed back, away from the other (the targets hold them only
  // softly).
  EXPECT_LT(a.col(0).mean(), bodies[0].start.col(0).mean() - 0.5);
  EXPECT_NEAR(a.col(0).mean(), -b.col(0).mean(), 0.05);
}

TEST(JointDeformerTest, ADiscPressedBetweenTwoSpheresEntersNeither) {
  // Half-axes 20 x 20 x 4 mm, each sphere carried 3.5 mm into it from
  // either side: one-sided pins push the disc out of one sphere into the
  // other, round after round.
  const mesh::IndexedMesh sphere = mesh::make_icosphere(4, kJointSphereRadius);
  mesh::IndexedMesh disc = mesh::make_icosphere(4, 1.0);
  disc.V = disc.V * Vector3d(20, 20, 4).asDiagonal();
  const VolumeDeformer sphere_deformer(sphere);
  const VolumeDeformer disc_deformer(disc);
  const double offset = 4.0 + kJointSphereRadius - 3.5;
  const std::vector<JointBody> bodies = {
      body(disc_deformer, disc.V),
      body(sphere_deformer, sphere.V.rowwise() + RowVector3d(0, 0, offset)),
      body(sphere_deformer, sphere.V.rowwise() + RowVector3d(0, 0, -offset))};

  const JointResult result = solve_jointly(bodies, options());
  EXPECT_TRUE(result.converged);
  EXPECT_EQ(result.largest_group, 3);
  const MatrixX3d& d = result.bodies[0].x;
  for (std::size_t s = 1; s <= 2; ++s) {
    EXPECT_LE(deepest_inside(d, result.bodies[s].x, sphere.F), 0.05) << "sphere " << s;
    EXPECT_LE(deepest_inside(result.bodies[s].x, d, disc.F), 0.05) << "sphere " << s;
  }
  for (const DeformResult& r : result.bodies) EXPECT_LT(std::abs(r.volume_error), 1e-9);
}

TEST(JointDeformerTest, BodiesThatDoNotTouchAreLeftAlone) {
  const mesh::IndexedMesh rest = mesh::make_icosphere(3, kJointSphereRadius);
  const VolumeDeformer deformer(rest);
  const std::vector<JointBody> bodies = {body(deformer, rest.V.rowwise() + RowVector3d(-25, 0, 0)),
                                         body(deformer, rest.V.rowwise() + RowVector3d(25, 0, 0))};
  const JointResult result = solve_jointly(bodies, options());
  EXPECT_EQ(result.rounds, 0);
  EXPECT_EQ(result.largest_group, 0);
  EXPECT_TRUE(result.converged);
  for (std::size_t m = 0; m < 2; ++m) {
    EXPECT_EQ(result.bodies[m].x, bodies[m].start);
    EXPECT_EQ(result.couplings[m], 0);
  }
}

TEST(JointDeformerTest, PinsAndNewContactsHoldInTheJointSolve) {
  // The left sphere's vertex furthest from the overlap is pinned 1 mm out;
  // a "bone" (the half-space y > 12) takes in the right sphere's top, which
  // its query pushes back out.
  const mesh::IndexedMesh rest = mesh::make_icosphere(4, kJointSphereRadius);
  const VolumeDeformer deformer(rest);
  std::vector<JointBody> bodies = {body(deformer, rest.V.rowwise() + RowVector3d(-18, 0, 0)),
                                   body(deformer, rest.V.rowwise() + RowVector3d(18, 0, 0))};
  Eigen::Index far = 0;
  bodies[0].start.col(0).minCoeff(&far);
  const Vector3d pinned = bodies[0].start.row(far).transpose() + Vector3d(-1, 0, 0);
  bodies[0].contacts.push_back({static_cast<int>(far), pinned, 0, 0.0});
  bodies[1].query = [](const MatrixX3d& x, const std::vector<char>& active) {
    std::vector<Contact> found;
    for (Eigen::Index v = 0; v < x.rows(); ++v) {
      if (active[static_cast<std::size_t>(v)] == 0 && x(v, 1) > kBone)
        found.push_back({static_cast<int>(v), Vector3d(x(v, 0), kBone, x(v, 2)), 0, 0.0});
    }
    return found;
  };
  const JointResult result = solve_jointly(bodies, options());
  EXPECT_TRUE(result.converged);
  EXPECT_LT((result.bodies[0].x.row(far).transpose() - pinned).norm(), 0.01);
  EXPECT_LE(result.bodies[1].x.col(1).maxCoeff(), kBone + 0.01);
  EXPECT_GT(result.bodies[1].contacts.size(), 0U);
  EXPECT_LE(deepest_inside(result.bodies[0].x, result.bodies[1].x, rest.F), 0.05);
  for (const DeformResult& r : result.bodies) EXPECT_LT(std::abs(r.volume_error), 1e-9);
}

TEST(JointDeformerTest, BadInputIsRefusedWithTheReason) {
  const mesh::IndexedMesh rest = mesh::make_icosphere(2, kJointSphereRadius);
  const VolumeDeformer deformer(rest);
  const JointBody good = body(deformer, rest.V);
  auto message = [](const std::vector<JointBody>& bodies, const JointOptions& o) {
    try {
      (void)solve_jointly(bodies, o);
    } catch (const InvalidInputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  JointBody no_deformer = good;
  no_deformer.deformer = nullptr;
  EXPECT_NE(message({good, no_deformer}, options()).find("body 1 has no deformer"),
            std::string::npos);
  JointBody short_start = good;
  short_start.start.conservativeResize(3, 3);
  EXPECT_NE(message({short_start}, options()).find("finite rows"), std::string::npos);
  JointBody nan_start = good;
  nan_start.start(0, 0) = std::nan("");
  EXPECT_NE(message({nan_start}, options()).find("finite rows"), std::string::npos);
  JointBody bad_pin = good;
  bad_pin.contacts.push_back({static_cast<int>(rest.V.rows()), Vector3d::Zero(), 0, 0.0});
  EXPECT_NE(message({bad_pin}, options()).find("contact"), std::string::npos);
  JointOptions no_weight = options();
  no_weight.coupling.weight = 0.0;
  EXPECT_NE(message({good}, no_weight).find("coupling weight"), std::string::npos);
  JointOptions no_rounds = options();
  no_rounds.max_rounds = 0;
  EXPECT_NE(message({good}, no_rounds).find("max_rounds"), std::string::npos);
}

}  // namespace
}  // namespace mmm::wrapping

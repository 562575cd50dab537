#include "core/mesh/winding_number.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

constexpr double kMajor = 10.0;
constexpr double kMinor = 3.0;

// Signed distance to the analytic torus around z (negative in the tube).
double torus_implicit(const Eigen::Vector3d& p) {
  const double ring = std::hypot(p.x(), p.y()) - kMajor;
  return std::hypot(ring, p.z()) - kMinor;
}

double longest_edge(const IndexedMesh& mesh) {
  double longest = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const double length = (mesh.V.row(mesh.F(f, k)) - mesh.V.row(mesh.F(f, (k + 1) % 3))).norm();
      longest = std::max(longest, length);
    }
  }
  return longest;
}

using test::uniform_in;

// A cube [-1, 1]^3 without its top face (z = 1): an open surface.
IndexedMesh open_box() {
  const IndexedMesh box = make_box(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
  IndexedMesh open;
  open.V = box.V;
  open.F.resize(10, 3);
  int kept = 0;
  for (int f = 0; f < box.num_faces(); ++f) {
    const bool on_top =
        box.V(box.F(f, 0), 2) == 1 && box.V(box.F(f, 1), 2) == 1 && box.V(box.F(f, 2), 2) == 1;
    if (!on_top) open.F.row(kept++) = box.F.row(f);
  }
  EXPECT_EQ(kept, 10);
  return open;
}

TEST(WindingNumberTest, TorusTubeIsInsideHoleAndOutsideAreNot) {
  const IndexedMesh torus = make_torus(kMajor, kMinor, 96, 48);
  const AabbTree tree(torus);
  const WindingNumber winding(tree);
  EXPECT_TRUE(winding.is_inside(Eigen::Vector3d(10, 0, 0)));     // tube centre circle
  EXPECT_TRUE(winding.is_inside(Eigen::Vector3d(0, -11.5, 1)));  // in the tube
  EXPECT_FALSE(winding.is_inside(Eigen::Vector3d(0, 0, 0)));     // centre of the hole
  EXPECT_FALSE(winding.is_inside(Eigen::Vector3d(5, 0, 0)));     // hole, near the tube
  EXPECT_FALSE(winding.is_inside(Eigen::Vector3d(20, 0, 0)));    // beside
  EXPECT_FALSE(winding.is_inside(Eigen::Vector3d(10, 0, 5)));    // above the tube
  // Deep in the tube and far away the value itself is an integer; the far-field
  // expansion at beta = 2 errs by up to ~5e-3 on such meshes (see the header).
  EXPECT_NEAR(winding.at(Eigen::Vector3d(10, 0, 0)), 1.0, 1e-2);
  EXPECT_NEAR(winding.at(Eigen::Vector3d(0, 0, 0)), 0.0, 1e-2);
  EXPECT_NEAR(winding.at(Eigen::Vector3d(100, -200, 50)), 0.0, 1e-2);
}

TEST(WindingNumberTest, TorusInsideTestMatchesImplicitFunctionAwayFromSurface) {
  const IndexedMesh torus = make_torus(kMajor, kMinor, 96, 48);
  const AabbTree tree(torus);
  const WindingNumber winding(tree);
  // The implicit distance is 1-Lipschitz and zero at every vertex, and each
  // point of a face is within one edge length of a vertex of that face: the
  // polyhedron lies where |implicit| <= longest edge. Beyond that band the
  // polyhedron's inside (the winding number is constant on each side) is the
  // analytic one.
  const double margin = longest_edge(torus);
  EXPECT_LT(margin, 1.0);
  std::mt19937 rng(42);
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-15, -15, -5), Eigen::Vector3d(15, 15, 5));
  int compared = 0;
  int inside = 0;
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d q = uniform_in(box, rng);
    const double implicit = torus_implicit(q);
    if (std::abs(implicit) <= margin) continue;
    ++compared;
    inside += implicit < 0 ? 1 : 0;
    ASSERT_EQ(winding.is_inside(q), implicit < 0) << "at " << q.transpose();
  }
  // The sample really exercises both sides (tube ~20% of the box volume).
  EXPECT_GT(compared, 3000);
  EXPECT_GT(inside, 300);
}

// Largest |fast - exact| at 1000 uniform points of the mesh's box grown by
// half its size on each side.
double worst_fast_error(const IndexedMesh& surface, std::mt19937& rng) {
  const AabbTree tree(surface);
  const WindingNumber winding(tree);
  Eigen::AlignedBox3d box = tree.bounds();
  box.extend(box.min() - 0.5 * box.sizes()).extend(box.max() + 0.5 * box.sizes());
  double worst = 0;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d q = uniform_in(box, rng);
    worst = std::max(worst, std::abs(winding.at(q) - winding_number_exact(surface, q)));
  }
  return worst;
}

TEST(WindingNumberTest, FastAgreesWithExactAtRandomPoints) {
  std::mt19937 rng(9);
  // The second-order expansion at beta = 2 errs by up to ~5e-3 here (header);
  // 1e-2 is also far below what the inside test (threshold 1/2) can tolerate.
  EXPECT_LT(worst_fast_error(make_torus(kMajor, kMinor, 64, 32), rng), 1e-2);
  EXPECT_LT(worst_fast_error(make_icosphere(3, 4.0, Eigen::Vector3d(1, 1, 1)), rng), 1e-2);
  EXPECT_LT(worst_fast_error(open_box(), rng), 1e-2);
}

TEST(WindingNumberTest, ClosedSphereGivesOneInsideAndZeroOutside) {
  const IndexedMesh sphere = make_icosphere(2, 2.0);
  // Solid angles of a closed surface sum to exactly 4 pi or 0: only rounding
  // of 320 atan2 terms remains.
  EXPECT_NEAR(winding_number_exact(sphere, Eigen::Vector3d(0.3, -0.2, 0.5)), 1.0, 1e-12);
  EXPECT_NEAR(winding_number_exact(sphere, Eigen::Vector3d(3, 1, 0)), 0.0, 1e-12);
  // Inside a face the value is the mean of the two sides: the face itself
  // contributes 0 there and jumps by 1 across, the others are continuous.
  const Eigen::Vector3d face_centre =
      (sphere.V.row(sphere.F(5, 0)) + sphere.V.row(sphere.F(5, 1)) + sphere.V.row(sphere.F(5, 2)))
          .transpose() /
      3.0;
  EXPECT_NEAR(winding_number_exact(sphere, face_centre), 0.5, 1e-12);
}

TEST(WindingNumberTest, OpenBoxStaysNearOneDeepInside) {
  const IndexedMesh open = open_box();
  const AabbTree tree(open);
  const WindingNumber winding(tree);
  // At the centre every side subtends 4 pi / 6: without the top w = 5/6.
  EXPECT_NEAR(winding_number_exact(open, Eigen::Vector3d::Zero()), 5.0 / 6.0, 1e-12);
  // Near the bottom the hole (a 2 x 2 square at height d = 1.9) subtends
  // 4 atan(a b / (d sqrt(a^2 + b^2 + d^2))) with a = b = 1; w = 1 - that / 4 pi.
  const Eigen::Vector3d deep(0, 0, -0.9);
  const double d = 1.9;
  const double hole = 4.0 * std::atan(1.0 / (d * std::sqrt(2.0 + d * d)));
  const double expected = 1.0 - hole / (4.0 * std::numbers::pi);
  EXPECT_GT(expected, 0.9);
  EXPECT_NEAR(winding_number_exact(open, deep), expected, 1e-12);  // rounding of 10 terms
  EXPECT_NEAR(winding.at(deep), expected, 1e-2);                   // far-field error, see above
  EXPECT_TRUE(winding.is_inside(deep));
  EXPECT_TRUE(winding.is_inside(Eigen::Vector3d(0.5, -0.5, 0)));
  EXPECT_FALSE(winding.is_inside(Eigen::Vector3d(0, 0, 3)));  // above the hole
  EXPECT_FALSE(winding.is_inside(Eigen::Vector3d(3, 0, 0)));
}

TEST(WindingNumberTest, RejectsInvalidInput) {
  const AabbTree tree(make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1)));
  EXPECT_THROW(WindingNumber(tree, {.beta = 1.0}), InvalidInputError);
  EXPECT_THROW(WindingNumber(tree, {.beta = std::nan("")}), InvalidInputError);
  const WindingNumber winding(tree);
  EXPECT_THROW((void)winding.at(Eigen::Vector3d::Constant(INFINITY)), InvalidInputError);
  IndexedMesh bad = make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1));
  bad.F(0, 0) = -1;
  EXPECT_THROW((void)winding_number_exact(bad, Eigen::Vector3d::Zero()), InvalidInputError);
}

TEST(WindingNumberTest, GluteusMediusCentroidIsInsideAndFarPointIsNot) {
  const IndexedMesh muscle =
      read_mesh(test::data_dir() / "vhf" / "Right" / "VHF_Right_Muscle_GluteusMedius_smooth.stl");
  // Volume centroid by the divergence theorem over the tetrahedra (origin,
  // face); the volume is positive for a closed outward-oriented surface.
  double volume = 0;
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  for (Eigen::Index f = 0; f < muscle.num_faces(); ++f) {
    const Eigen::Vector3d a = muscle.V.row(muscle.F(f, 0)).transpose();
    const Eigen::Vector3d b = muscle.V.row(muscle.F(f, 1)).transpose();
    const Eigen::Vector3d c = muscle.V.row(muscle.F(f, 2)).transpose();
    const double tetrahedron = a.dot(b.cross(c)) / 6.0;
    volume += tetrahedron;
    weighted += tetrahedron * (a + b + c) / 4.0;
  }
  ASSERT_GT(volume, 0.0);
  const Eigen::Vector3d centroid = weighted / volume;

  const AabbTree tree(muscle);
  const WindingNumber winding(tree);
  // The gluteus medius is thick enough around its centroid for it to lie
  // inside; an independent witness is the parity of ray crossings.
  for (const Eigen::Vector3d& direction :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, -1)}) {
    EXPECT_EQ(tree.all_hits(centroid, direction).size() % 2, 1U);
  }
  EXPECT_TRUE(winding.is_inside(centroid));
  // A closed surface gives an integer: only the far-field error remains.
  EXPECT_NEAR(winding.at(centroid), 1.0, 1e-2);
  EXPECT_NEAR(winding_number_exact(muscle, centroid), 1.0, 1e-9);  // rounding of 26K terms

  const Eigen::Vector3d far_away = centroid + Eigen::Vector3d(1000, 0, 0);  // 1 m
  EXPECT_FALSE(winding.is_inside(far_away));
  // 1 m away the whole muscle is one far node, and every order of the
  // expansion of a closed surface vanishes: only rounding remains.
  EXPECT_NEAR(winding.at(far_away), 0.0, 1e-6);
}

}  // namespace
}  // namespace mmm::mesh

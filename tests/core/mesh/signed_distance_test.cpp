#include "core/mesh/signed_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"

namespace mmm::mesh {
namespace {

Eigen::Vector3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

TEST(SignedDistanceTest, IcosphereMatchesDistanceToSphere) {
  const double radius = 10.0;
  const IndexedMesh sphere = make_icosphere(5, radius);
  const SignedDistance distance(sphere);
  // Every point of the polyhedron is between radius - gap and radius from the
  // centre, so at |q| = s its distance differs from |s - radius| by at most gap.
  const double gap = test::icosphere_gap(sphere, radius, Eigen::Vector3d::Zero());
  EXPECT_GT(gap, 1e-3);
  EXPECT_LT(gap, 5e-3);
  const double tolerance = gap + 1e-12;  // plus rounding at this 10 mm scale
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> inner(0.0, radius - 0.1);
  std::uniform_real_distribution<double> outer(radius + 0.1, 3 * radius);
  for (int i = 0; i < 1000; ++i) {
    // Radii keep 0.1 mm (>> gap) from the surface so the sign is unambiguous.
    const double s = i % 2 == 0 ? inner(rng) : outer(rng);
    const Eigen::Vector3d q = s * random_direction(rng);
    const double got = distance.at(q);
    ASSERT_NEAR(got, s - radius, tolerance) << "at |q| = " << s;
    ASSERT_EQ(got < 0, s < radius);
  }
  EXPECT_NEAR(distance.at(Eigen::Vector3d::Zero()), -radius, tolerance);
}

TEST(SignedDistanceTest, BoxDistancesAreExact) {
  const SignedDistance distance(make_box(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)));
  // Planar faces: the polyhedron is the shape, only rounding remains.
  EXPECT_NEAR(distance.at(Eigen::Vector3d(0, 0, 0)), -1.0, 1e-12);
  EXPECT_NEAR(distance.at(Eigen::Vector3d(0.2, 0.7, -0.1)), -0.3, 1e-12);
  EXPECT_NEAR(distance.at(Eigen::Vector3d(3, 0, 0)), 2.0, 1e-12);
  EXPECT_NEAR(distance.at(Eigen::Vector3d(2, 2, 0)), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(distance.at(Eigen::Vector3d(2, 2, 2)), std::sqrt(3.0), 1e-12);
}

TEST(SignedDistanceTest, BatchMatchesSinglePoints) {
  const SignedDistance distance(make_torus(5.0, 2.0, 48, 24));
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> coordinate(-9.0, 9.0);
  Eigen::MatrixX3d points(200, 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    points.row(i) << coordinate(rng), coordinate(rng), coordinate(rng) / 3;
  }
  const Eigen::VectorXd batch = distance.at(points);
  ASSERT_EQ(batch.size(), points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    // Same computation point by point: identical.
    EXPECT_EQ(batch[i], distance.at(Eigen::Vector3d(points.row(i).transpose())));
  }
  EXPECT_EQ(distance.at(Eigen::MatrixX3d(0, 3)).size(), 0);
}

TEST(SignedDistanceTest, MovedObjectStaysValid) {
  SignedDistance original(make_icosphere(2, 1.0));
  const double before = original.at(Eigen::Vector3d(0.1, 0.2, 0.3));
  const SignedDistance moved(std::move(original));
  EXPECT_EQ(moved.at(Eigen::Vector3d(0.1, 0.2, 0.3)), before);
  EXPECT_EQ(&moved.winding().tree(), &moved.tree());
}

TEST(SignedDistanceTest, RejectsInvalidInput) {
  EXPECT_THROW(SignedDistance{IndexedMesh{}}, InvalidInputError);
  const IndexedMesh box = make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1));
  SignedDistance::Options options;
  options.winding.beta = 0.5;
  EXPECT_THROW(SignedDistance(box, options), InvalidInputError);
  const SignedDistance distance(box);
  EXPECT_THROW((void)distance.at(Eigen::Vector3d(std::nan(""), 0, 0)), InvalidInputError);
}

}  // namespace
}  // namespace mmm::mesh

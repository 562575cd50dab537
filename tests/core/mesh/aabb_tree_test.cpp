#include "core/mesh/aabb_tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

Eigen::Vector3d vertex(const IndexedMesh& mesh, int face, int corner) {
  return mesh.V.row(mesh.F(face, corner)).transpose();
}

double segment_squared_distance(const Eigen::Vector3d& q, const Eigen::Vector3d& p0,
                                const Eigen::Vector3d& p1) {
  const Eigen::Vector3d edge = p1 - p0;
  const double length2 = edge.squaredNorm();
  const double s = length2 > 0 ? std::clamp(edge.dot(q - p0) / length2, 0.0, 1.0) : 0.0;
  return (q - (p0 + s * edge)).squaredNorm();
}

// Reference written independently of the tree's Voronoi-region code: the
// projection onto the plane when it falls inside the triangle, otherwise the
// nearest of the three edges.
double triangle_squared_distance(const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                                 const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  if (n.squaredNorm() > 0) {
    const Eigen::Vector3d projected = q - n * (n.dot(q - a) / n.squaredNorm());
    const bool inside = (b - a).cross(projected - a).dot(n) >= 0 &&
                        (c - b).cross(projected - b).dot(n) >= 0 &&
                        (a - c).cross(projected - c).dot(n) >= 0;
    if (inside) return (q - projected).squaredNorm();
  }
  return std::min({segment_squared_distance(q, a, b), segment_squared_distance(q, b, c),
                   segment_squared_distance(q, c, a)});
}

double brute_force_squared_distance(const IndexedMesh& mesh, const Eigen::Vector3d& q) {
  double best = std::numeric_limits<double>::infinity();
  for (int f = 0; f < mesh.num_faces(); ++f) {
    best = std::min(best, triangle_squared_distance(q, vertex(mesh, f, 0), vertex(mesh, f, 1),
                                                    vertex(mesh, f, 2)));
  }
  return best;
}

using test::uniform_in;

// Compares the tree with brute force at `count` uniform points of `box`.
void expect_closest_points_match(const IndexedMesh& mesh, const Eigen::AlignedBox3d& box, int count,
                                 unsigned seed) {
  const AabbTree tree(mesh);
  std::mt19937 rng(seed);
  const double scale = box.diagonal().norm();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d q = uniform_in(box, rng);
    const AabbTree::ClosestPoint closest = tree.closest_point(q);
    const double expected = std::sqrt(brute_force_squared_distance(mesh, q));
    const double got = std::sqrt(closest.squared_distance);
    // Both sides are exact up to a few roundings of coordinates of size
    // `scale` (~1e-15 * scale); 1e-12 relative leaves room for that even at
    // distances a thousand times smaller than the mesh.
    ASSERT_NEAR(got, expected, 1e-12 * std::max(expected, 1e-3 * scale)) << "query " << i;
    // The answer is consistent: the point lies on the face given by its
    // barycentric weights (rounding of size 1e-15 * scale again).
    ASSERT_GE(closest.face, 0);
    ASSERT_LT(closest.face, mesh.num_faces());
    const Eigen::Vector3d from_weights = closest.barycentric[0] * vertex(mesh, closest.face, 0) +
                                         closest.barycentric[1] * vertex(mesh, closest.face, 1) +
                                         closest.barycentric[2] * vertex(mesh, closest.face, 2);
    ASSERT_LT((from_weights - closest.point).norm(), 1e-12 * scale);
    ASSERT_NEAR(closest.barycentric.sum(), 1.0, 1e-12);  // weights sum to one up to rounding
    ASSERT_GE(closest.barycentric.minCoeff(), -1e-12);   // inside the face up to rounding
    ASSERT_NEAR((q - closest.point).squaredNorm(), closest.squared_distance,
                1e-12 * std::max(closest.squared_distance, 1e-6 * scale * scale));
  }
}

TEST(AabbTreeTest, ClosestPointMatchesBruteForceAroundTorus) {
  const IndexedMesh torus = make_torus(10.0, 3.0, 64, 32);
  expect_closest_points_match(
      torus, Eigen::AlignedBox3d(Eigen::Vector3d(-16, -16, -6), Eigen::Vector3d(16, 16, 6)), 2000,
      1);
}

TEST(AabbTreeTest, ClosestPointMatchesBruteForceAroundIcosphere) {
  const Eigen::Vector3d center(1, -2, 3);
  const IndexedMesh sphere = make_icosphere(3, 5.0, center);
  expect_closest_points_match(sphere,
                              Eigen::AlignedBox3d(center - Eigen::Vector3d::Constant(9),
                                                  center + Eigen::Vector3d::Constant(9)),
                              2000, 2);
}

TEST(AabbTreeTest, QueryOnAVertexHasZeroDistance) {
  const IndexedMesh sphere = make_icosphere(2, 3.0);
  const AabbTree tree(sphere);
  for (int v = 0; v < sphere.num_vertices(); v += 17) {
    const AabbTree::ClosestPoint closest = tree.closest_point(sphere.V.row(v).transpose());
    // The vertex itself is a candidate; only rounding of a - a + ... remains.
    EXPECT_LT(closest.squared_distance, 1e-28);
  }
}

TEST(AabbTreeTest, LeafSizeDoesNotChangeTheAnswer) {
  const IndexedMesh torus = make_torus(5.0, 1.0, 40, 20);
  const AabbTree fine(torus, {.max_leaf_size = 1});
  const AabbTree coarse(torus, {.max_leaf_size = 64});
  EXPECT_GT(fine.num_nodes(), coarse.num_nodes());
  // Median split: depth is at most ceil(log2 #F) with one face per leaf.
  EXPECT_LE(fine.depth(), static_cast<int>(std::ceil(std::log2(torus.num_faces()))));
  std::mt19937 rng(3);
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-8, -8, -3), Eigen::Vector3d(8, 8, 3));
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d q = uniform_in(box, rng);
    // The same faces are compared with the same arithmetic: identical results.
    EXPECT_EQ(fine.closest_point(q).squared_distance, coarse.closest_point(q).squared_distance);
  }
}

TEST(AabbTreeTest, ClosestPointWithinHonoursTheBound) {
  const IndexedMesh box = make_box(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
  const AabbTree tree(box);
  const Eigen::Vector3d q(3, 0.2, -0.1);  // 2 mm from the face x = 1
  const auto inside_bound = tree.closest_point_within(q, 4.0);
  ASSERT_TRUE(inside_bound.has_value());
  EXPECT_DOUBLE_EQ(inside_bound->squared_distance, 4.0);
  EXPECT_EQ(inside_bound->squared_distance, tree.closest_point(q).squared_distance);
  EXPECT_FALSE(tree.closest_point_within(q, 3.99).has_value());
  EXPECT_FALSE(tree.closest_point_within(q, -1.0).has_value());
}

TEST(AabbTreeTest, DegenerateTrianglesGiveFiniteAnswers) {
  IndexedMesh mesh;
  mesh.V.resize(5, 3);
  mesh.V << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 5, 5, 5;
  mesh.F.resize(3, 3);
  mesh.F << 0, 1, 2,  // collinear: a segment from (0,0,0) to (2,0,0)
      4, 4, 4,        // a single point
      0, 1, 3;        // a proper triangle
  const AabbTree tree(mesh);
  std::mt19937 rng(5);
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-3, -3, -3), Eigen::Vector3d(8, 8, 8));
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d q = uniform_in(box, rng);
    const AabbTree::ClosestPoint closest = tree.closest_point(q);
    ASSERT_TRUE(closest.point.allFinite());
    // Same rounding argument as the smooth cases (scale ~10 mm).
    ASSERT_NEAR(closest.squared_distance, brute_force_squared_distance(mesh, q),
                1e-12 * std::max(1.0, closest.squared_distance));
  }
}

TEST(AabbTreeTest, TreeKeepsItsOwnCopyOfTheMesh) {
  const auto make_tree = [] {
    const IndexedMesh box = make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3));
    return AabbTree(box);
  };
  const AabbTree tree = make_tree();  // the box above is gone
  EXPECT_EQ(tree.mesh().num_faces(), 12);
  EXPECT_TRUE(tree.bounds().isApprox(
      Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3))));
  EXPECT_DOUBLE_EQ(tree.closest_point(Eigen::Vector3d(0.5, 1, 5)).squared_distance, 4.0);
}

TEST(AabbTreeTest, RejectsInvalidInput) {
  EXPECT_THROW(AabbTree(IndexedMesh{}), InvalidInputError);
  IndexedMesh box = make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1));
  EXPECT_THROW(AabbTree(box, {.max_leaf_size = 0}), InvalidInputError);
  IndexedMesh bad_index = box;
  bad_index.F(3, 1) = 8;
  EXPECT_THROW(AabbTree{bad_index}, InvalidInputError);
  IndexedMesh bad_vertex = box;
  bad_vertex.V(2, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(AabbTree{bad_vertex}, InvalidInputError);

  const AabbTree tree(box);
  const Eigen::Vector3d nan_point = Eigen::Vector3d::Constant(std::nan(""));
  EXPECT_THROW((void)tree.closest_point(nan_point), InvalidInputError);
  EXPECT_THROW((void)tree.first_hit(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()),
               InvalidInputError);
  EXPECT_THROW((void)tree.all_hits(nan_point, Eigen::Vector3d::UnitX()), InvalidInputError);
}

// Box [-1, 1] x [-2, 2] x [-3, 3] for the ray cases below.
IndexedMesh ray_box() { return make_box(Eigen::Vector3d(-1, -2, -3), Eigen::Vector3d(1, 2, 3)); }

TEST(AabbTreeTest, RayEntersAndLeavesBox) {
  const IndexedMesh box = ray_box();
  const AabbTree tree(box);
  const Eigen::Vector3d origin(-5, 0.3, 0.2);
  // Unit direction: faces x = -1 and x = 1 at t = 4 and 6. The arithmetic is
  // a handful of exact or once-rounded operations: 1e-12 covers it.
  const auto first = tree.first_hit(origin, Eigen::Vector3d::UnitX());
  ASSERT_TRUE(first.has_value());
  EXPECT_NEAR(first->t, 4.0, 1e-12);
  const Eigen::Vector3d hit_point = first->barycentric[0] * vertex(box, first->face, 0) +
                                    first->barycentric[1] * vertex(box, first->face, 1) +
                                    first->barycentric[2] * vertex(box, first->face, 2);
  EXPECT_LT((hit_point - Eigen::Vector3d(-1, 0.3, 0.2)).norm(), 1e-12);

  const std::vector<AabbTree::RayHit> hits = tree.all_hits(origin, Eigen::Vector3d::UnitX());
  ASSERT_EQ(hits.size(), 2U);
  EXPECT_NEAR(hits[0].t, 4.0, 1e-12);
  EXPECT_NEAR(hits[1].t, 6.0, 1e-12);

  // t is in units of the direction: twice as long, half the t.
  const auto scaled = tree.all_hits(origin, Eigen::Vector3d(2, 0, 0));
  ASSERT_EQ(scaled.size(), 2U);
  EXPECT_NEAR(scaled[0].t, 2.0, 1e-12);
  EXPECT_NEAR(scaled[1].t, 3.0, 1e-12);

  // t_max cuts the exit; an origin inside sees only the exit.
  EXPECT_EQ(tree.all_hits(origin, Eigen::Vector3d::UnitX(), 5.0).size(), 1U);
  EXPECT_FALSE(tree.first_hit(origin, Eigen::Vector3d::UnitX(), 3.9).has_value());
  const auto exit_only = tree.all_hits(Eigen::Vector3d(0, 0.3, 0.2), Eigen::Vector3d::UnitX());
  ASSERT_EQ(exit_only.size(), 1U);
  EXPECT_NEAR(exit_only[0].t, 1.0, 1e-12);
  // Pointing away: nothing behind the origin counts.
  EXPECT_FALSE(tree.first_hit(origin, -Eigen::Vector3d::UnitX()).has_value());
}

TEST(AabbTreeTest, RayThatMissesHitsNothing) {
  const AabbTree tree(ray_box());
  const Eigen::Vector3d origin(-5, 2.5, 0);
  EXPECT_FALSE(tree.first_hit(origin, Eigen::Vector3d::UnitX()).has_value());
  EXPECT_TRUE(tree.all_hits(origin, Eigen::Vector3d::UnitX()).empty());
  const Eigen::Vector3d oblique(1, 1, 1);
  EXPECT_FALSE(tree.first_hit(Eigen::Vector3d(5, 5, 5), oblique).has_value());
}

TEST(AabbTreeTest, RayParallelToFacesHitsOnlyTheFacesItCrosses) {
  const IndexedMesh box = ray_box();
  const AabbTree tree(box);
  // Along y, inside the x and z slabs: two zero direction components. Faces
  // y = -2 and y = 2 at t = 3 and 7; the x and z faces are parallel.
  const auto hits = tree.all_hits(Eigen::Vector3d(0.5, -5, -1), Eigen::Vector3d::UnitY());
  ASSERT_EQ(hits.size(), 2U);
  EXPECT_NEAR(hits[0].t, 3.0, 1e-12);
  EXPECT_NEAR(hits[1].t, 7.0, 1e-12);
  for (const auto& hit : hits) {
    const Eigen::Vector3d normal = (vertex(box, hit.face, 1) - vertex(box, hit.face, 0))
                                       .cross(vertex(box, hit.face, 2) - vertex(box, hit.face, 0));
    EXPECT_EQ(normal.x(), 0.0);  // the hit faces are y faces
    EXPECT_EQ(normal.z(), 0.0);
  }
  // Parallel to the x faces and just outside the slab x in [-1, 1]: a miss.
  EXPECT_TRUE(tree.all_hits(Eigen::Vector3d(-1.5, -5, 0), Eigen::Vector3d::UnitY()).empty());
}

TEST(AabbTreeTest, RayThroughSharedEdgesCountsEachCrossingOnce) {
  const IndexedMesh box = ray_box();
  const AabbTree tree(box);
  // Along -z through (0, 0): crosses the diagonals that split the faces
  // z = 3 and z = -3 into two triangles each, at t = 7 and 13.
  const auto through_diagonals =
      tree.all_hits(Eigen::Vector3d(0, 0, 10), -Eigen::Vector3d::UnitZ());
  ASSERT_EQ(through_diagonals.size(), 2U);
  EXPECT_NEAR(through_diagonals[0].t, 7.0, 1e-12);
  EXPECT_NEAR(through_diagonals[1].t, 13.0, 1e-12);
  const auto first = tree.first_hit(Eigen::Vector3d(0, 0, 10), -Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(first.has_value());
  EXPECT_NEAR(first->t, 7.0, 1e-12);

  // Along y in the plane x = -1: meets the box edges x = -1, y = -2 and
  // x = -1, y = 2 (at t = 3 and 7) and slides along the face x = -1 between.
  const auto along_face = tree.all_hits(Eigen::Vector3d(-1, -5, 0.5), Eigen::Vector3d::UnitY());
  ASSERT_EQ(along_face.size(), 2U);
  EXPECT_NEAR(along_face[0].t, 3.0, 1e-12);
  EXPECT_NEAR(along_face[1].t, 7.0, 1e-12);
}

TEST(AabbTreeTest, RayToSphereCentreHitsAtDistanceMinusRadius) {
  const double radius = 10.0;
  const Eigen::Vector3d center(1, 2, 3);
  const IndexedMesh sphere = make_icosphere(4, radius, center);
  const AabbTree tree(sphere);
  // The polyhedron lies between radius - gap and radius from the centre, so a
  // ray towards the centre enters at a distance in [d - r, d - r + gap] and
  // leaves at [d + r - gap, d + r].
  const double gap = test::icosphere_gap(sphere, radius, center);
  EXPECT_LT(gap, 0.02);  // edge ~0.66 mm: gap ~ edge^2 / (6 r) ~ 7e-3 mm
  std::mt19937 rng(17);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> distance_of(12.0, 40.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d away =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const double distance = distance_of(rng);
    const double speed = 0.5 + i % 3;  // direction lengths 0.5, 1.5, 2.5
    const Eigen::Vector3d origin = center + distance * away;
    const Eigen::Vector3d direction = -speed * away;
    const auto first = tree.first_hit(origin, direction);
    ASSERT_TRUE(first.has_value());
    // Slack 1e-9 mm for the rounding of t at these sizes.
    EXPECT_GE(first->t * speed, distance - radius - 1e-9);
    EXPECT_LE(first->t * speed, distance - radius + gap + 1e-9);
    const auto hits = tree.all_hits(origin, direction);
    ASSERT_EQ(hits.size(), 2U) << "ray " << i;
    EXPECT_EQ(hits[0].t, first->t);
    EXPECT_GE(hits[1].t * speed, distance + radius - gap - 1e-9);
    EXPECT_LE(hits[1].t * speed, distance + radius + 1e-9);
  }
}

IndexedMesh gluteus_medius() {
  return read_mesh(test::data_dir() / "vhf" / "Right" /
                   "VHF_Right_Muscle_GluteusMedius_smooth.stl");
}

TEST(AabbTreeTest, GluteusMediusClosestPointsMatchBruteForce) {
  const IndexedMesh muscle = gluteus_medius();
  ASSERT_GT(muscle.num_faces(), 10000);
  Eigen::AlignedBox3d box;
  for (Eigen::Index v = 0; v < muscle.num_vertices(); ++v) box.extend(muscle.V.row(v).transpose());
  // Queries through the muscle's box grown by a fifth on each side: inside,
  // near and away from the surface (~100-170 mm boxes, coordinates ~1000 mm,
  // still far inside the 1e-12 relative rounding argument above).
  const Eigen::Vector3d margin = 0.2 * box.sizes();
  expect_closest_points_match(muscle, Eigen::AlignedBox3d(box.min() - margin, box.max() + margin),
                              200, 23);
}

}  // namespace
}  // namespace mmm::mesh

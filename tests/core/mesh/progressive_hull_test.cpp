#include "core/mesh/progressive_hull.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <string>

#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/primitives.h"
#include "core/mesh/signed_distance.h"
#include "tests/core/mesh/mesh_test_helpers.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using test::euler_characteristic;
using test::is_closed_edge_manifold;

// Largest signed distance to `hull` over the input's vertices and face
// centroids, computed here rather than trusted from the report: the hull must
// contain the whole input surface, not only the points it was built from.
double farthest_outside(const IndexedMesh& input, const IndexedMesh& hull) {
  const SignedDistance distance(hull);
  double farthest = distance.at(input.V).maxCoeff();
  for (Eigen::Index f = 0; f < input.num_faces(); ++f) {
    const Eigen::Vector3d centroid =
        (input.V.row(input.F(f, 0)) + input.V.row(input.F(f, 1)) + input.V.row(input.F(f, 2)))
            .transpose() /
        3.0;
    farthest = std::max(farthest, distance.at(centroid));
  }
  return farthest;
}

// The surface of the cube [-h, h]^3 as an n by n grid of squares per side,
// each split in two, outward; vertices of the top side (z = h) inside radius
// `dent_radius` of the z axis sink by depth * cos^2(pi r / (2 dent_radius)),
// a smooth dent that leaves the rest of the top flat.
IndexedMesh make_dented_cube(int n, double h, double dent_radius, double depth) {
  std::map<std::array<int, 3>, int> index;
  std::vector<Eigen::Vector3d> points;
  auto vertex = [&](const std::array<int, 3>& lattice) {
    const auto [it, inserted] = index.emplace(lattice, static_cast<int>(points.size()));
    if (inserted) {
      Eigen::Vector3d p(lattice[0], lattice[1], lattice[2]);
      p = p * (2.0 * h / n) - Eigen::Vector3d::Constant(h);
      const double r = std::hypot(p.x(), p.y());
      if (lattice[2] == n && r < dent_radius) {
        const double s = std::cos(std::numbers::pi * r / (2.0 * dent_radius));
        p.z() -= depth * s * s;
      }
      points.push_back(p);
    }
    return it->second;
  };
  std::vector<std::array<int, 3>> faces;
  // Each side: a fixed axis at 0 or n, and two running axes (u, v) ordered
  // so that u x v points outward.
  for (int axis = 0; axis < 3; ++axis) {
    for (const int side : {0, n}) {
      int u = (axis + 1) % 3;
      int v = (axis + 2) % 3;
      if (side == 0) std::swap(u, v);
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          auto corner = [&](int di, int dj) {
            std::array<int, 3> lattice{};
            lattice[static_cast<size_t>(axis)] = side;
            lattice[static_cast<size_t>(u)] = i + di;
            lattice[static_cast<size_t>(v)] = j + dj;
            return vertex(lattice);
          };
          faces.push_back({corner(0, 0), corner(1, 0), corner(1, 1)});
          faces.push_back({corner(0, 0), corner(1, 1), corner(0, 1)});
        }
      }
    }
  }
  IndexedMesh cube;
  cube.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t k = 0; k < points.size(); ++k) cube.V.row(static_cast<Eigen::Index>(k)) = points[k];
  cube.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t k = 0; k < faces.size(); ++k) {
    cube.F.row(static_cast<Eigen::Index>(k)) << faces[k][0], faces[k][1], faces[k][2];
  }
  return cube;
}

// Runs progressive_hull and returns the message of the InvalidInputError it
// must throw ("" when it throws nothing).
std::string error_message(const IndexedMesh& mesh, const ProgressiveHullOptions& options) {
  try {
    (void)progressive_hull(mesh, options);
  } catch (const InvalidInputError& error) {
    return error.what();
  }
  return "";
}

TEST(ProgressiveHullTest, IcosphereHullIsAClosedOutwardSphereAroundEveryInputPoint) {
  const IndexedMesh sphere = make_icosphere(3, 10.0);
  ASSERT_EQ(sphere.num_faces(), 1280);
  ProgressiveHullOptions options;
  options.target_faces = 100;
  ProgressiveHullReport report;
  const IndexedMesh hull = progressive_hull(sphere, options, &report);
  // A closed mesh loses two faces per collapse: 1280 - 2k reaches 100 exactly.
  EXPECT_EQ(hull.num_faces(), 100);
  EXPECT_EQ(report.faces_before, 1280);
  EXPECT_EQ(report.faces_after, 100);
  EXPECT_TRUE(is_closed_edge_manifold(hull.F));
  EXPECT_EQ(euler_characteristic(hull), 2);
  const double volume_before = test::signed_volume(sphere);
  const double volume_after = test::signed_volume(hull);
  EXPECT_GT(volume_after, 0.0) << "outward";
  EXPECT_GE(volume_after, volume_before);
  // A regular dodecahedron around a sphere (12 faces) has 1.33 times its
  // volume. The excess scales with the face area: 100 even faces would give
  // ~1.04. The greedy hull's faces are uneven (measured 1.10); 1.2 allows
  // for that without accepting a hull twice as loose as measured.
  EXPECT_LT(volume_after, 1.2 * volume_before);
  // The report agrees with an independent volume computation (both are sums
  // of the same tetrahedra, so only summation order differs).
  EXPECT_NEAR(report.volume_before, volume_before, 1e-9 * volume_before);
  EXPECT_NEAR(report.volume_after, volume_after, 1e-9 * volume_after);
  EXPECT_EQ(report.vertices_outside, 0);
  EXPECT_LE(report.max_outside_mm, kProgressiveHullOnSurfaceTolerance);
  EXPECT_LE(farthest_outside(sphere, hull), kProgressiveHullOnSurfaceTolerance);
}

TEST(ProgressiveHullTest, TorusHullKeepsItsHoleAndStaysBelowTheConvexHull) {
  const double major = 30.0;
  const double minor = 10.0;
  const IndexedMesh torus = make_torus(major, minor, 48, 24);
  ProgressiveHullOptions options;
  options.target_faces = 300;
  ProgressiveHullReport report;
  const IndexedMesh hull = progressive_hull(torus, options, &report);
  EXPECT_EQ(hull.num_faces(), 300);
  EXPECT_TRUE(is_closed_edge_manifold(hull.F));
  EXPECT_EQ(euler_characteristic(hull), 0) << "a collapse closed the hole";
  EXPECT_EQ(report.vertices_outside, 0);
  EXPECT_LE(farthest_outside(torus, hull), kProgressiveHullOnSurfaceTolerance);
  const double volume_after = test::signed_volume(hull);
  EXPECT_GE(volume_after, test::signed_volume(torus));
  // Convex hull of the smooth torus: the cylinder r <= R, |z| <= r plus the
  // outer half disc swept around the axis (Pappus: area pi r^2 / 2 at
  // distance R + 4 r / (3 pi)); it contains the inscribed mesh's convex hull.
  // 90.3 cm^3 against 58.4 cm^3 for the mesh torus: a hull that fills the
  // hole gets near it, a tight one stays near the torus (measured 63.9,
  // 0.71 of the convex hull).
  const double convex_hull = 2.0 * std::numbers::pi * major * major * minor +
                             std::numbers::pi * minor * minor / 2.0 * 2.0 * std::numbers::pi *
                                 (major + 4.0 * minor / (3.0 * std::numbers::pi));
  EXPECT_LT(volume_after, 0.85 * convex_hull);
  // The hole stays open: the axis is outside the hull, about as far from it
  // as the inner side of a tube circumscribed by a hexagon (corner radius
  // 10 / cos 30 deg = 11.5 mm around the 30 mm circle: 18.5 mm from the
  // axis; measured 17.3 mm). A hull bridging the hole would reach the axis.
  const SignedDistance distance(hull);
  EXPECT_GT(distance.at(Eigen::Vector3d::Zero()), 15.0);
}

TEST(ProgressiveHullTest, DentedCubeHullKeepsFlatSidesAndMostOfTheDent) {
  // Flat sides make the placement LP degenerate (a whole plane of positions
  // adds no volume); the dent is the non-convex part.
  const double h = 20.0;
  const IndexedMesh cube = make_dented_cube(12, h, 12.0, 10.0);
  ASSERT_EQ(cube.num_faces(), 6 * 2 * 144);
  ASSERT_TRUE(is_closed_edge_manifold(cube.F));
  ProgressiveHullOptions options;
  options.target_faces = 40;
  ProgressiveHullReport report;
  const IndexedMesh hull = progressive_hull(cube, options, &report);
  EXPECT_EQ(hull.num_faces(), 40);
  EXPECT_TRUE(is_closed_edge_manifold(hull.F));
  EXPECT_EQ(euler_characteristic(hull), 2);
  EXPECT_EQ(report.vertices_outside, 0);
  EXPECT_LE(farthest_outside(cube, hull), kProgressiveHullOnSurfaceTolerance);
  // Flat collapses add no volume, so the hull never leaves the cube: its
  // bounding box is the cube's up to rounding of 20 mm coordinates (4e-15;
  // exact as measured). A nudge along a mean normal at the cube's edges
  // would show here as ~1e-7 mm.
  const Eigen::AlignedBox3d box = bounding_box(hull);
  EXPECT_LT((box.min() + Eigen::Vector3d::Constant(h)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((box.max() - Eigen::Vector3d::Constant(h)).cwiseAbs().maxCoeff(), 1e-12);
  // The convex hull is the full cube; the dent holds 1.35 cm^3 of its
  // 64 cm^3. 40 faces leave the flat sides two triangles each and ~28 for
  // the dent, which fill 20% of it (measured); a hull that keeps less than
  // half of the dent is on its way to the convex hull.
  const double cube_volume = 8.0 * h * h * h;
  const double dented_volume = test::signed_volume(cube);
  const double volume_after = test::signed_volume(hull);
  EXPECT_GE(volume_after, dented_volume);
  EXPECT_LT(volume_after, cube_volume - 0.5 * (cube_volume - dented_volume));
}

TEST(ProgressiveHullTest, DentedCubeAtTwelveFacesIsItsBox) {
  // The coarsest hull of a dented cube that keeps its corners is the cube
  // itself: 12 triangles, 8 corners, no dent left.
  const double h = 20.0;
  const IndexedMesh cube = make_dented_cube(12, h, 12.0, 10.0);
  ProgressiveHullOptions options;
  options.target_faces = 12;
  ProgressiveHullReport report;
  const IndexedMesh hull = progressive_hull(cube, options, &report);
  EXPECT_EQ(hull.num_faces(), 12);
  EXPECT_EQ(hull.num_vertices(), 8);
  EXPECT_EQ(report.vertices_outside, 0);
  // Corners land on intersections of the side planes: exact up to rounding
  // of 20 mm coordinates (4e-15 mm; exact as measured).
  for (Eigen::Index v = 0; v < hull.num_vertices(); ++v) {
    EXPECT_LT((hull.V.row(v).cwiseAbs().array() - h).abs().maxCoeff(), 1e-12) << hull.V.row(v);
  }
  // 64000 mm^3 up to the rounding of the corners (1e-12 mm x 2400 mm^2).
  EXPECT_NEAR(test::signed_volume(hull), 8.0 * h * h * h, 1e-8);
}

TEST(ProgressiveHullTest, GluteusMediusToOneThousandFacesContainsTheMuscle) {
  const IndexedMesh muscle = read_mesh(mmm::test::data_dir() / "vhf" / "Right" /
                                       "VHF_Right_Muscle_GluteusMedius_smooth.stl");
  // Preconditions: the welded STL is a closed sphere-like surface (26K faces).
  ASSERT_TRUE(is_closed_edge_manifold(muscle.F));
  ASSERT_EQ(euler_characteristic(muscle), 2);
  ASSERT_GT(muscle.num_faces(), 20000);
  ProgressiveHullOptions options;
  options.target_faces = 1000;
  ProgressiveHullReport report;
  const IndexedMesh hull = progressive_hull(muscle, options, &report);
  std::cout << "GluteusMedius: " << report.faces_before << " -> " << report.faces_after
            << " faces, volume " << report.volume_before / 1e3 << " -> "
            << report.volume_after / 1e3 << " cm^3 (+"
            << 100.0 * (report.volume_after / report.volume_before - 1.0) << "%), "
            << report.vertices_outside << " vertices outside (max " << report.max_outside_mm
            << " mm)\n";
  EXPECT_EQ(hull.num_faces(), 1000);
  EXPECT_EQ(report.faces_after, 1000);
  EXPECT_TRUE(is_closed_edge_manifold(hull.F));
  EXPECT_EQ(euler_characteristic(hull), 2);
  EXPECT_EQ(report.vertices_outside, 0);
  EXPECT_LE(report.max_outside_mm, kProgressiveHullOnSurfaceTolerance);
  EXPECT_LE(farthest_outside(muscle, hull), kProgressiveHullOnSurfaceTolerance);
  EXPECT_GT(report.volume_after, report.volume_before);
  // A 1000-face hull of a smooth ~200 mm muscle: faces ~10 mm across bulge
  // over the curved surface by about their sagitta; a few percent of the
  // volume (measured 2.7%). 10% would mean a hull no longer shaped like the
  // muscle.
  EXPECT_LT(report.volume_after, 1.10 * report.volume_before);
}

TEST(ProgressiveHullTest, TargetAtOrAboveTheFaceCountReturnsTheInput) {
  const IndexedMesh sphere = make_icosphere(2);
  ProgressiveHullOptions options;
  options.target_faces = sphere.num_faces();
  ProgressiveHullReport report;
  const IndexedMesh same = progressive_hull(sphere, options, &report);
  EXPECT_EQ(same.V, sphere.V);
  EXPECT_EQ(same.F, sphere.F);
  EXPECT_EQ(report.faces_after, sphere.num_faces());
  EXPECT_EQ(report.volume_after, report.volume_before);
  EXPECT_EQ(report.vertices_outside, 0);
}

TEST(ProgressiveHullTest, RejectsATargetBelowATetrahedron) {
  ProgressiveHullOptions options;
  options.target_faces = 3;
  EXPECT_NE(error_message(make_icosphere(2), options).find("target_faces must be >= 4"),
            std::string::npos);
  options.target_faces = 100;
  options.max_normal_deviation_degrees = 0.0;
  EXPECT_NE(error_message(make_icosphere(2), options).find("max_normal_deviation_degrees"),
            std::string::npos);
}

TEST(ProgressiveHullTest, RejectsAnOpenMesh) {
  IndexedMesh open = make_icosphere(2);
  open.F.conservativeResize(open.F.rows() - 1, 3);
  ProgressiveHullOptions options;
  options.target_faces = 100;
  const std::string message = error_message(open, options);
  EXPECT_NE(message.find("open (3 boundary edges in 1 holes)"), std::string::npos) << message;
  EXPECT_NE(message.find("fill the holes"), std::string::npos) << message;
}

TEST(ProgressiveHullTest, RejectsAnInwardMesh) {
  IndexedMesh inward = make_icosphere(2);
  inward.F.col(1).swap(inward.F.col(2));
  ProgressiveHullOptions options;
  options.target_faces = 100;
  const std::string message = error_message(inward, options);
  EXPECT_NE(message.find("point inward"), std::string::npos) << message;
  EXPECT_NE(message.find("reverse every face"), std::string::npos) << message;
}

TEST(ProgressiveHullTest, RejectsANonManifoldMesh) {
  // Two spheres sharing one vertex: closed along every edge, but that vertex
  // has two separate fans (a bow-tie).
  const IndexedMesh a = make_icosphere(1, 1.0, Eigen::Vector3d::Zero());
  IndexedMesh both;
  both.V.resize(2 * a.V.rows() - 1, 3);
  both.V.topRows(a.V.rows()) = a.V;
  both.F.resize(2 * a.F.rows(), 3);
  both.F.topRows(a.F.rows()) = a.F;
  // The second sphere is the first mirrored through its vertex 0 (so they
  // touch there); its vertex 0 maps onto the first's, the others follow it.
  const Eigen::RowVector3d pivot = a.V.row(0);
  for (Eigen::Index v = 1; v < a.V.rows(); ++v) {
    both.V.row(a.V.rows() + v - 1) = 2.0 * pivot - a.V.row(v);
  }
  for (Eigen::Index f = 0; f < a.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int v = a.F(f, k);
      both.F(a.F.rows() + f, k) = v == 0 ? 0 : static_cast<int>(a.V.rows()) + v - 1;
    }
  }
  // A point reflection (det -1) turns the copy inside out: swap two corners
  // of each of its faces to make it outward again.
  both.F.bottomRows(a.F.rows()).col(1).swap(both.F.bottomRows(a.F.rows()).col(2));
  ProgressiveHullOptions options;
  options.target_faces = 40;
  const std::string message = error_message(both, options);
  EXPECT_NE(message.find("not two-manifold"), std::string::npos) << message;
}

TEST(ProgressiveHullTest, RejectsDegenerateFaces) {
  // Vertex 0 moved onto the midpoint of the opposite edge of face 0: still
  // closed, but that face has zero area and no outward side.
  IndexedMesh flat = make_icosphere(2);
  const int a = flat.F(0, 0);
  flat.V.row(a) = 0.5 * (flat.V.row(flat.F(0, 1)) + flat.V.row(flat.F(0, 2)));
  ProgressiveHullOptions options;
  options.target_faces = 100;
  const std::string message = error_message(flat, options);
  EXPECT_NE(message.find("degenerate"), std::string::npos) << message;
}

}  // namespace
}  // namespace mmm::mesh

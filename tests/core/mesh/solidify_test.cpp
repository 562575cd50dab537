#include "core/mesh/solidify.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

constexpr double kRadius = 10.0;  // mm
constexpr double kSpacing = 0.5;  // mm, grid spacing h of these tests
constexpr double kSqrt3 = 1.7320508075688772;

double sphere_volume(double radius) { return 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3); }

// Every vertex marching tetrahedra makes lies on a tetrahedron edge whose ends
// are on opposite sides of the surface (|w| - 1/2 changes sign). Away from the
// surface w is 0 or 1 (up to the winding number's ~1e-2 far-field error), so
// the vertex sits at the fraction t = 0.5 +- 0.01 of that edge; the longest
// edge is the cube's main diagonal h sqrt(3). Hence a vertex is at most
// 0.51 h sqrt(3) from the input surface.
double vertex_offset_bound(double h) { return 0.51 * kSqrt3 * h; }

void expect_watertight_outward(const IndexedMesh& mesh) {
  const MeshCheckReport report = check_mesh(mesh);
  EXPECT_TRUE(report.watertight()) << ::testing::PrintToString(report.problems());
  EXPECT_TRUE(report.closed());
  EXPECT_TRUE(report.manifold());
  EXPECT_TRUE(report.orientation_consistent());
  EXPECT_GT(signed_volume(mesh), 0.0);
}

// Distances of the vertices from `center`: smallest and largest.
std::pair<double, double> radius_range(const IndexedMesh& mesh, const Eigen::Vector3d& center) {
  double low = std::numeric_limits<double>::infinity();
  double high = 0.0;
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    const double r = (mesh.V.row(v).transpose() - center).norm();
    low = std::min(low, r);
    high = std::max(high, r);
  }
  return {low, high};
}

IndexedMesh flipped(IndexedMesh mesh) {
  mesh.F.col(1).swap(mesh.F.col(2));
  return mesh;
}

// The mesh without the listed faces (vertices kept).
IndexedMesh without_faces(const IndexedMesh& mesh, const std::vector<int>& removed) {
  IndexedMesh result;
  result.V = mesh.V;
  result.F.resize(mesh.num_faces() - static_cast<Eigen::Index>(removed.size()), 3);
  Eigen::Index kept = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (std::find(removed.begin(), removed.end(), f) == removed.end()) {
      result.F.row(kept++) = mesh.F.row(f);
    }
  }
  return result;
}

IndexedMesh concatenated(const IndexedMesh& a, const IndexedMesh& b) {
  IndexedMesh result;
  result.V.resize(a.num_vertices() + b.num_vertices(), 3);
  result.V << a.V, b.V;
  result.F.resize(a.num_faces() + b.num_faces(), 3);
  result.F << a.F, (b.F.array() + static_cast<int>(a.num_vertices())).matrix();
  return result;
}

TEST(SolidifyTest, IcosphereBecomesClosedOutwardSphereOfTheRightSize) {
  const IndexedMesh sphere = make_icosphere(4, kRadius);
  const IndexedMesh solid = solidify(sphere, {.grid_spacing_mm = kSpacing});
  expect_watertight_outward(solid);
  EXPECT_EQ(check_mesh(solid).connected_components, 1);
  EXPECT_EQ(check_mesh(solid).euler_characteristic, 2);  // a sphere's topology

  // The input lies between the sphere and its inscribed faces (gap below
  // ~0.01 mm at 4 subdivisions); every output vertex is within the bound
  // above of the input.
  const double gap = test::icosphere_gap(sphere, kRadius, Eigen::Vector3d::Zero());
  const double offset = vertex_offset_bound(kSpacing);
  const auto [low, high] = radius_range(solid, Eigen::Vector3d::Zero());
  EXPECT_GT(low, kRadius - gap - offset);
  EXPECT_LT(high, kRadius + offset);
  // So the solid lies between the spheres of those radii (the output's faces
  // sag inward of its vertices by at most e^2 / (8 r) ~ 0.01 mm for edges
  // e < h sqrt(3), folded into the lower radius).
  const double volume = signed_volume(solid);
  EXPECT_GT(volume, sphere_volume(kRadius - gap - offset - 0.01));
  EXPECT_LT(volume, sphere_volume(kRadius + offset));
  // The placement errors along the edges have both signs and average out
  // over ~10^4 vertices: measured within 0.5 % of 4/3 pi r^3; 2 % (a mean
  // radial bias of h / 15) still catches a systematic shift of the surface.
  EXPECT_NEAR(volume, sphere_volume(kRadius), 0.02 * sphere_volume(kRadius));
}

TEST(SolidifyTest, SphereWithHolesStillGivesAClosedSurfaceOfAboutTheVolume) {
  // 2 subdivisions: faces of ~3 mm, several times the grid spacing, so each
  // missing face is a real hole to close.
  const IndexedMesh sphere = make_icosphere(2, kRadius);
  const IndexedMesh holed = without_faces(sphere, {0, 57, 123, 200, 301});
  ASSERT_FALSE(check_mesh(holed).closed());
  const IndexedMesh solid = solidify(holed, {.grid_spacing_mm = kSpacing});
  expect_watertight_outward(solid);
  EXPECT_EQ(check_mesh(solid).connected_components, 1);
  // Across a hole w falls to 1/2 on the hole's plane, so the surface closes
  // it near the missing face: the volume stays that of the closed input up to
  // the grid error (the 2 % of the whole-sphere test) plus the five face
  // cones lost (at most 5 faces * 4.4 mm^2 * the 0.5 mm cap height).
  const double closed_volume = signed_volume(sphere);
  EXPECT_NEAR(signed_volume(solid), closed_volume, 0.02 * closed_volume + 11.0);
}

TEST(SolidifyTest, InwardOrientedSphereGivesTheSameOutwardSolid) {
  const IndexedMesh sphere = make_icosphere(3, kRadius);
  const IndexedMesh inward = flipped(sphere);
  ASSERT_LT(signed_volume(inward), 0.0);
  const IndexedMesh from_outward = solidify(sphere, {.grid_spacing_mm = kSpacing});
  const IndexedMesh from_inward = solidify(inward, {.grid_spacing_mm = kSpacing});
  expect_watertight_outward(from_inward);
  // |w| is the same field for both orientations, up to the winding number's
  // far-field error (< 1e-2: flipping the faces changes the rounding of the
  // face centroids, hence the tree's splits and its expansions). That moves
  // each vertex along its edge (<= h sqrt 3) by at most 1e-2 of it, so the
  // volumes differ by at most twice that times the area (22 mm^3; measured
  // 0.007).
  const double area = 4 * std::numbers::pi * kRadius * kRadius;
  EXPECT_NEAR(signed_volume(from_inward), signed_volume(from_outward),
              2 * 1e-2 * kSqrt3 * kSpacing * area);
  EXPECT_NEAR(signed_volume(from_inward), sphere_volume(kRadius), 0.02 * sphere_volume(kRadius));
}

TEST(SolidifyTest, TwoDisjointSpheresGiveTwoComponents) {
  const IndexedMesh a = make_icosphere(3, 5.0, Eigen::Vector3d(-8, 0, 0));
  const IndexedMesh b = make_icosphere(3, 4.0, Eigen::Vector3d(9, 2, 1));
  const IndexedMesh solid = solidify(concatenated(a, b), {.grid_spacing_mm = kSpacing});
  expect_watertight_outward(solid);
  EXPECT_EQ(check_mesh(solid).connected_components, 2);
  // The spheres are 4 mm apart, far more than the grid spacing: the volumes
  // of the two inputs add up, within the 2 % of the single-sphere test
  // (measured 0.9 %: the relative error grows as h / r).
  const double expected = signed_volume(a) + signed_volume(b);
  EXPECT_NEAR(signed_volume(solid), expected, 0.02 * expected);
}

TEST(SolidifyTest, BoxWithFacesOnGridPlanesBecomesAClosedBox) {
  // A box whose faces fall exactly on grid planes (w = 1/2 there, the
  // ambiguous value): one padding cell keeps the outermost grid points
  // outside, so the surface is still closed.
  const IndexedMesh box = make_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 3, 2));
  const IndexedMesh solid = solidify(box, {.grid_spacing_mm = 0.25, .padding_cells = 1});
  expect_watertight_outward(solid);
  const Eigen::AlignedBox3d bounds = bounding_box(solid);
  // The surface passes through the midpoints of edges crossing the faces:
  // within half the longest tetrahedron edge of the box's faces.
  const double slack = vertex_offset_bound(0.25);
  EXPECT_LT((bounds.min() - Eigen::Vector3d(0, 0, 0)).cwiseAbs().maxCoeff(), slack);
  EXPECT_LT((bounds.max() - Eigen::Vector3d(4, 3, 2)).cwiseAbs().maxCoeff(), slack);
}

TEST(SolidifyTest, BadInputThrows) {
  const IndexedMesh sphere = make_icosphere(1, kRadius);
  EXPECT_THROW((void)solidify(sphere, {.grid_spacing_mm = 0.0}), InvalidInputError);
  EXPECT_THROW((void)solidify(sphere, {.grid_spacing_mm = -1.0}), InvalidInputError);
  EXPECT_THROW(
      (void)solidify(sphere, {.grid_spacing_mm = std::numeric_limits<double>::quiet_NaN()}),
      InvalidInputError);
  EXPECT_THROW((void)solidify(sphere, {.grid_spacing_mm = std::numeric_limits<double>::infinity()}),
               InvalidInputError);
  // (20 mm / 0.005 mm)^3 = 6.4e10 grid points, above the 50 million limit.
  EXPECT_THROW((void)solidify(sphere, {.grid_spacing_mm = 0.005}), InvalidInputError);
  EXPECT_THROW((void)solidify(IndexedMesh{}), InvalidInputError);
  IndexedMesh broken = sphere;
  broken.V(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)solidify(broken), InvalidInputError);
}

// gait2392's pelvis.vtp is an open shell with holes (RealDataTest): solidify
// turns it into a closed outward 2-manifold.
TEST(SolidifyTest, Gait2392PelvisBecomesWatertight) {
  IndexedMesh pelvis = read_mesh(test::data_dir() / "gait2392/Geometry/pelvis.vtp");
  pelvis.V *= 1000.0;  // m -> mm
  ASSERT_FALSE(check_mesh(pelvis).closed());
  const IndexedMesh solid = solidify(pelvis, {.grid_spacing_mm = 3.0});
  expect_watertight_outward(solid);
  // The solid keeps the bone's extent: its bounding box matches the input's
  // to within the vertex bound plus one cell (features thinner than h, as
  // the thin iliac wing's rim, may erode by up to a cell).
  const Eigen::AlignedBox3d in = bounding_box(pelvis);
  const Eigen::AlignedBox3d out = bounding_box(solid);
  const double slack = vertex_offset_bound(3.0) + 3.0;
  EXPECT_LT((in.min() - out.min()).cwiseAbs().maxCoeff(), slack);
  EXPECT_LT((in.max() - out.max()).cwiseAbs().maxCoeff(), slack);
}

}  // namespace
}  // namespace mmm::mesh

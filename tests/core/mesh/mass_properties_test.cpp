#include "core/mesh/mass_properties.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::mesh {
namespace {

constexpr double kPi = std::numbers::pi;

// Sums of a few dozen terms of order one: rounding stays near 1e-15, so
// 1e-12 is "exact" with a wide margin.
constexpr double kExact = 1e-12;

TEST(MassPropertiesTest, UnitCubeIsExact) {
  const IndexedMesh cube = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  const MassProperties p = mass_properties(cube);
  EXPECT_NEAR(p.volume, 1.0, kExact);
  EXPECT_NEAR(p.area, 6.0, kExact);
  EXPECT_TRUE(p.solid);
  EXPECT_TRUE(p.centroid.isApprox(Eigen::Vector3d::Constant(0.5), kExact));
  // Unit-density unit cube: moment of inertia about any centroidal axis is
  // (1^2 + 1^2) / 12 = 1/6; the second moment is 1/12 on the diagonal.
  EXPECT_TRUE(p.second_moment.isApprox(Eigen::Matrix3d::Identity() / 12.0, kExact));
  EXPECT_TRUE(p.principal_moments.isApprox(Eigen::Vector3d::Constant(1.0 / 6.0), kExact));
}

TEST(MassPropertiesTest, BoxFarFromOriginKeepsPrecision) {
  // VHF meshes sit ~600 mm from the origin; the result must not suffer.
  const Eigen::Vector3d lo(600, 400, 800);
  const IndexedMesh box = make_box(lo, lo + Eigen::Vector3d(40, 20, 10));
  const MassProperties p = mass_properties(box);
  EXPECT_NEAR(p.volume, 8000.0, 8000.0 * kExact);
  EXPECT_NEAR(p.area, 2 * (800.0 + 400.0 + 200.0), kExact * 2800);
  EXPECT_TRUE(p.centroid.isApprox(lo + Eigen::Vector3d(20, 10, 5), kExact));
  // Long axis first: x (40 mm), then y (20), then z (10).
  EXPECT_NEAR(std::abs(p.principal_axes(0, 0)), 1.0, kExact);
  EXPECT_NEAR(std::abs(p.principal_axes(1, 1)), 1.0, kExact);
  EXPECT_NEAR(std::abs(p.principal_axes(2, 2)), 1.0, kExact);
  EXPECT_NEAR(p.principal_axes.determinant(), 1.0, kExact);
}

TEST(MassPropertiesTest, InwardOrientationGivesNegativeVolume) {
  IndexedMesh cube = make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(2.0));
  cube.F.col(1).swap(cube.F.col(2));
  EXPECT_NEAR(signed_volume(cube), -8.0, kExact);
  const MassProperties p = mass_properties(cube);
  EXPECT_NEAR(p.volume, -8.0, kExact);
  EXPECT_GT(p.second_moment.trace(), 0.0);
}

TEST(MassPropertiesTest, PolygonalCylinderVolumeIsExact) {
  // A prism over a regular n-gon: volume n/2 r^2 sin(2 pi / n) h exactly.
  const int n = 32;
  const IndexedMesh cylinder = make_cylinder(3.0, 7.0, n);
  const double expected = n / 2.0 * 9.0 * std::sin(2 * kPi / n) * 7.0;
  EXPECT_NEAR(signed_volume(cylinder), expected, expected * kExact);
}

// Icosphere convergence: the inscribed polyhedron's volume and area err by
// O(h^2), h the edge length, and h halves with each subdivision, so each
// level divides the error by about 4. We check the order (ratio between 3.5
// and 4.5: 4 minus higher-order terms) and the level-6 values (81920 faces):
// an edge there subtends about 1.107 / 64 rad (the icosahedron's 1.107 rad
// halved six times), a face's circumradius about that / sqrt(3) = 0.010 rad,
// so faces sit at most r (1 - cos 0.010) = 5e-5 r inside the sphere; volume
// loses at most ~3x and area ~2x that relative depth. 2e-4 leaves room for the
// uneven triangles that projecting the subdivision onto the sphere creates.
TEST(MassPropertiesTest, IcosphereConvergesAtSecondOrder) {
  const double r = 10.0;
  const double sphere_volume = 4.0 / 3.0 * kPi * r * r * r;
  const double sphere_area = 4.0 * kPi * r * r;
  double previous_volume_error = 0;
  double previous_area_error = 0;
  for (int level = 2; level <= 6; ++level) {
    const MassProperties p = mass_properties(make_icosphere(level, r));
    const double volume_error = (sphere_volume - p.volume) / sphere_volume;
    const double area_error = (sphere_area - p.area) / sphere_area;
    EXPECT_GT(volume_error, 0.0) << "inscribed polyhedron must be smaller";
    EXPECT_GT(area_error, 0.0);
    if (level > 2) {
      EXPECT_GT(previous_volume_error / volume_error, 3.5) << "level " << level;
      EXPECT_LT(previous_volume_error / volume_error, 4.5) << "level " << level;
      EXPECT_GT(previous_area_error / area_error, 3.5) << "level " << level;
      EXPECT_LT(previous_area_error / area_error, 4.5) << "level " << level;
    }
    if (level == 6) {
      EXPECT_LT(volume_error, 2e-4);
      EXPECT_LT(area_error, 2e-4);
      EXPECT_LT(p.centroid.norm(), 1e-9 * r);  // symmetric up to rounding
    }
    previous_volume_error = volume_error;
    previous_area_error = area_error;
  }
}

TEST(MassPropertiesTest, OrientedBoxRecoversRotatedBox) {
  IndexedMesh box = make_box(Eigen::Vector3d(-30, -10, -5), Eigen::Vector3d(30, 10, 5));
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(500, 400, 900);
  box.V = (box.V * rotation.transpose()).rowwise() + shift.transpose();
  const OrientedBox obb = oriented_bounding_box(box);
  EXPECT_TRUE(obb.half_extents.isApprox(Eigen::Vector3d(30, 10, 5), 1e-9));
  EXPECT_TRUE(obb.center.isApprox(shift, 1e-9));
  EXPECT_NEAR(std::abs(obb.axes.col(0).dot(rotation.col(0))), 1.0, 1e-9);
  EXPECT_NEAR(obb.volume(), 60.0 * 20 * 10, 1e-6);
  for (Eigen::Index v = 0; v < box.V.rows(); ++v) {
    EXPECT_TRUE(obb.contains(box.V.row(v).transpose(), 1e-9));
  }
  EXPECT_FALSE(obb.contains(shift + rotation.col(1) * 11.0));
}

TEST(MassPropertiesTest, OpenSheetIsNotASolid) {
  IndexedMesh square;
  square.V.resize(4, 3);
  square.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  square.F.resize(2, 3);
  square.F << 0, 1, 2, 0, 2, 3;
  const MassProperties p = mass_properties(square);
  EXPECT_FALSE(p.solid);
  EXPECT_NEAR(p.area, 1.0, kExact);
  EXPECT_TRUE(p.centroid.isApprox(Eigen::Vector3d(0.5, 0.5, 0), kExact));
}

TEST(MassPropertiesTest, EmptyMeshIsRejected) {
  EXPECT_THROW(mass_properties(IndexedMesh{}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::mesh

#include "core/atlas/wrap_surface_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"

namespace mmm::atlas {
namespace {

// A bone standing in for the distal femur: an ellipsoidal end (semi-axes
// 30, 22, 18 mm, turned) sampled on a grid of directions, 1 m from the
// origin like the atlas.
const Eigen::Vector3d kBoneCentre(600.0, 420.0, 500.0);
const Eigen::Vector3d kBoneSemiAxes(30.0, 22.0, 18.0);
const Eigen::Matrix3d kBoneAxes =
    Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 0.4, 1.0).normalized()).toRotationMatrix();

Eigen::MatrixX3d ellipsoid_bone() {
  const int rings = 40;
  const int around = 80;
  Eigen::MatrixX3d vertices(rings * around, 3);
  for (int i = 0; i < rings; ++i) {
    const double polar = std::numbers::pi * (i + 0.5) / rings;
    for (int j = 0; j < around; ++j) {
      const double azimuth = 2.0 * std::numbers::pi * j / around;
      const Eigen::Vector3d n(std::sin(polar) * std::cos(azimuth),
                              std::sin(polar) * std::sin(azimuth), std::cos(polar));
      vertices.row(i * around + j) =
          (kBoneCentre + kBoneAxes * n.cwiseProduct(kBoneSemiAxes)).transpose();
    }
  }
  return vertices;
}

// A cylindrical bone (condyles about an axis, radius 21 mm, 60 mm long).
const Eigen::Vector3d kAxis = Eigen::Vector3d(1.0, 0.1, -0.05).normalized();

Eigen::MatrixX3d cylinder_bone() {
  const Eigen::Vector3d u = kAxis.unitOrthogonal();
  const Eigen::Vector3d v = kAxis.cross(u);
  Eigen::MatrixX3d vertices(60 * 72, 3);
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 72; ++j) {
      const double angle = 2.0 * std::numbers::pi * j / 72;
      vertices.row(i * 72 + j) =
          (kBoneCentre + (i - 29.5) * kAxis + 21.0 * (std::cos(angle) * u + std::sin(angle) * v))
              .transpose();
    }
  }
  return vertices;
}

TEST(WrapSurfaceFitTest, AnObstacleFittedToAKnownEllipsoidSurfaceRecoversIt) {
  WrapSurfaceRegion region;
  region.centre = kBoneCentre;
  region.radius_mm = 40.0;  // the whole end
  WrapSurfaceFitReport report;
  const WrapObstacle obstacle =
      fit_wrap_surface("end", "femur_r", WrapShape::kEllipsoid, ellipsoid_bone(), region,
                       Eigen::Vector3d(0, -1, 0), std::nullopt, {}, 2.0, &report);
  EXPECT_EQ(obstacle.shape, WrapShape::kEllipsoid);
  EXPECT_EQ(obstacle.bone, "femur_r");
  EXPECT_LT((obstacle.pose.translation() - kBoneCentre).norm(), 1e-4);
  // The semi-axes in some order, each along its true axis.
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d axis = obstacle.pose.linear().col(k);
    int match = 0;
    for (int j = 1; j < 3; ++j) {
      if (std::abs(axis.dot(kBoneAxes.col(j))) > std::abs(axis.dot(kBoneAxes.col(match)))) {
        match = j;
      }
    }
    EXPECT_NEAR(std::abs(axis.dot(kBoneAxes.col(match))), 1.0, 1e-6);
    EXPECT_NEAR(obstacle.radii[k], kBoneSemiAxes[match], 1e-4);
  }
  // x is the principal axis closest to the wrap side, pointing along it.
  EXPECT_GT(obstacle.pose.linear().col(0).dot(Eigen::Vector3d(0, -1, 0)), 0.5);
  EXPECT_NEAR(obstacle.pose.linear().determinant(), 1.0, 1e-9);
  EXPECT_EQ(obstacle.quadrant, "+x");
  EXPECT_LT(report.rms_mm, 1e-5);
  EXPECT_EQ(report.vertices, 40 * 80);
  EXPECT_DOUBLE_EQ(report.shrink, 1.0);
}

TEST(WrapSurfaceFitTest, ACylinderFittedToOneSideOfTheCondylesKeepsTheLinesPointsOutside) {
  WrapSurfaceRegion region;
  region.centre = kBoneCentre;
  region.radius_mm = 30.0;
  region.side = Eigen::Vector3d(0, -1, 0);  // the posterior half only
  // An origin on the surface (10 mm out from the axis after the offset)
  // shrinks the cylinder to leave it 2 mm outside.
  const Eigen::Vector3d origin =
      kBoneCentre +
      26.0 * (Eigen::Vector3d(0, -1, 0.3) - kAxis.dot(Eigen::Vector3d(0, -1, 0.3)) * kAxis)
                 .normalized();
  region.offset_mm = 8.0;
  WrapSurfaceFitReport report;
  const WrapObstacle obstacle = fit_wrap_surface(
      "condyles", "femur_r", WrapShape::kCylinder, cylinder_bone(), region,
      Eigen::Vector3d(0, -1, 0), Eigen::Vector3d::UnitX(),
      {{"far", kBoneCentre + Eigen::Vector3d(0, 0, 300)}, {"origin", origin}}, 2.0, &report);
  EXPECT_NEAR(std::abs(obstacle.pose.linear().col(2).dot(kAxis)), 1.0, 1e-8);
  EXPECT_NEAR(report.rms_mm, 0.0, 1e-6);
  EXPECT_LT(report.vertices, 60 * 72 / 2 + 60);  // one side of the region
  EXPECT_EQ(report.shrunk_by, "origin");
  EXPECT_NEAR(obstacle.radii.x(), 24.0, 1e-6);  // 21 + 8 = 29, shrunk to 26 - 2
  EXPECT_NEAR(report.shrink, 24.0 / 29.0, 1e-6);
  EXPECT_NEAR(distance_outside(obstacle, origin), 2.0, 1e-6);
  // x points to the wrap side (across the axis).
  EXPECT_LT(obstacle.pose.linear().col(0).y(), -0.9);
  EXPECT_NEAR(obstacle.pose.linear().col(0).dot(obstacle.pose.linear().col(2)), 0.0, 1e-12);
}

TEST(WrapSurfaceFitTest, ARegionWithTooFewVerticesIsAnErrorNamingTheSurface) {
  WrapSurfaceRegion region;
  region.centre = kBoneCentre + Eigen::Vector3d(0, 0, 500);
  try {
    (void)fit_wrap_surface("brim", "pelvis", WrapShape::kSphere, cylinder_bone(), region,
                           std::nullopt, std::nullopt, {}, 2.0);
    FAIL() << "no error";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("wrap surface brim: only 0 vertices of pelvis"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace mmm::atlas

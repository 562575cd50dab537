// Generalised cylinders: rotation-minimising frames do not turn over at an
// inflection point where Frenet-Serret frames do (a non-planar curve), keep
// a planar curve's plane normal exactly, and the tube around them is a
// watertight surface with the volume of the swept circle.

#include "core/fibres/tube.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"

namespace mmm::fibres {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

// (s, s^3 / 1600, s^4 / 64000), s in [-40, 40]: the curvature vanishes at
// s = 0 and the curve is not planar (y and z grow at different powers).
MatrixXd inflected(int n) {
  MatrixXd points(n, 3);
  for (int i = 0; i < n; ++i) {
    const double s = -40.0 + 80.0 * i / (n - 1);
    points.row(i) << s, s * s * s / 1600.0, s * s * s * s / 64000.0;
  }
  return points;
}

TEST(TubeTest, RotationMinimisingFramesDoNotTurnOverAtAnInflection) {
  const MatrixXd curve = inflected(200);
  const std::vector<Frame> rmf = rotation_minimising_frames(curve);
  const std::vector<Frame> frenet = frenet_frames(curve);
  ASSERT_EQ(rmf.size(), 200U);
  for (const Frame& frame : rmf) {
    EXPECT_NEAR(frame.tangent.norm(), 1.0, 1e-12);
    EXPECT_NEAR(frame.normal.norm(), 1.0, 1e-12);
    EXPECT_NEAR(frame.tangent.dot(frame.normal), 0.0, 1e-12);
    EXPECT_LT((frame.normal.cross(frame.binormal) - frame.tangent).norm(), 1e-12);
  }
  // The Frenet normal points to the centre of curvature, which changes side.
  EXPECT_GT(largest_twist_step(frenet), 0.9 * std::numbers::pi);
  EXPECT_LT(largest_twist_step(rmf), 1e-3);
}

TEST(TubeTest, APlanarCurvesFramesKeepThePlaneNormal) {
  // A sine in the plane z = 5, inflecting twice.
  MatrixXd curve(300, 3);
  for (int i = 0; i < 300; ++i) {
    const double s = 100.0 * i / 299;
    curve.row(i) << s, 20.0 * std::sin(s / 15.0), 5.0;
  }
  const std::vector<Frame> rmf = rotation_minimising_frames(curve, Vector3d(0, 0, 1));
  for (const Frame& frame : rmf) EXPECT_LT((frame.normal - Vector3d(0, 0, 1)).norm(), 1e-9);
  EXPECT_GT(largest_twist_step(frenet_frames(curve)), 0.9 * std::numbers::pi);
}

TEST(TubeTest, AStraightTubeIsAClosedPrismOfTheExactVolume) {
  const int sides = 24;
  MatrixXd line(11, 3);
  for (int i = 0; i < 11; ++i) line.row(i) << 3.0 * i, 1.0, -2.0;  // 30 mm
  const VectorXd radii = VectorXd::Constant(11, 4.0);
  const mesh::IndexedMesh tube = tube_mesh(line, radii, rotation_minimising_frames(line), sides);
  EXPECT_TRUE(mesh::check_mesh(tube).watertight());
  const double polygon = 0.5 * sides * std::sin(2.0 * std::numbers::pi / sides) * 16.0;
  EXPECT_NEAR(mesh::signed_volume(tube), polygon * 30.0, 1e-9);
}

TEST(TubeTest, ATaperingTubeOnTheInflectedCurveHasTheSweptVolume) {
  const int n = 400;
  const MatrixXd curve = inflected(n);
  VectorXd radii(n);
  double swept = 0.0;  // integral of pi r^2 along the centreline
  for (int i = 0; i < n; ++i) radii[i] = 3.0 - 1.5 * i / (n - 1);
  for (int i = 0; i + 1 < n; ++i) {
    const double r = 0.5 * (radii[i] + radii[i + 1]);
    swept += std::numbers::pi * r * r * (curve.row(i + 1) - curve.row(i)).norm();
  }
  const int sides = 64;
  const mesh::IndexedMesh tube = tube_mesh(curve, radii, rotation_minimising_frames(curve), sides);
  EXPECT_TRUE(mesh::check_mesh(tube).watertight());
  const double polygon_factor =
      0.5 * sides * std::sin(2.0 * std::numbers::pi / sides) / std::numbers::pi;
  EXPECT_NEAR(mesh::signed_volume(tube) / (polygon_factor * swept), 1.0, 0.01);
}

TEST(TubeTest, BadInputIsRefused) {
  const MatrixXd curve = inflected(10);
  EXPECT_THROW((void)rotation_minimising_frames(curve.topRows(1)), InvalidInputError);
  MatrixXd repeated = curve;
  repeated.row(4) = repeated.row(3);
  EXPECT_THROW((void)rotation_minimising_frames(repeated), InvalidInputError);
  MatrixXd nan = curve;
  nan(2, 2) = std::nan("");
  EXPECT_THROW((void)rotation_minimising_frames(nan), InvalidInputError);
  const Vector3d along = (curve.row(1) - curve.row(0)).transpose();
  EXPECT_THROW((void)rotation_minimising_frames(curve, along), InvalidInputError);
  const std::vector<Frame> frames = rotation_minimising_frames(curve);
  EXPECT_THROW((void)tube_mesh(curve, VectorXd::Ones(10), frames, 2), InvalidInputError);
  EXPECT_THROW((void)tube_mesh(curve, VectorXd::Ones(9), frames, 8), InvalidInputError);
  VectorXd negative = VectorXd::Ones(10);
  negative[5] = -1.0;
  EXPECT_THROW((void)tube_mesh(curve, negative, frames, 8), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fibres

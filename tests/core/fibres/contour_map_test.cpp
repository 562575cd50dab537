// Mean value coordinates of the unit square reproduce linear functions
// (so a square maps onto itself, and onto any affine image of itself,
// exactly), are non-negative and sum to one, and interpolate on the
// boundary; a loop is made consistent: counter-clockwise about the axis,
// starting on the reference side, at equal arc-length steps; a contour's
// start moved to match its neighbour recovers a known shift.

#include "core/fibres/contour_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

TEST(SquareBoundary, StartsAtTheRightMidpointAndRunsCounterClockwise) {
  const Eigen::MatrixX2d b = square_boundary(16);
  EXPECT_EQ(b.row(0), Eigen::RowVector2d(1.0, 0.5));
  EXPECT_EQ(b.row(1), Eigen::RowVector2d(1.0, 0.75));
  EXPECT_EQ(b.row(2), Eigen::RowVector2d(1.0, 1.0));  // a corner
  EXPECT_EQ(b.row(6), Eigen::RowVector2d(0.0, 1.0));
  EXPECT_EQ(b.row(15), Eigen::RowVector2d(1.0, 0.25));
  EXPECT_THROW((void)square_boundary(12), InvalidInputError);
}

TEST(SquareMeanValueWeights, ReproduceLinearFunctionsInsideAndOnTheBoundary) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::MatrixX2d boundary = square_boundary(64);
  // An affine image of the square: the weights map the square onto it exactly.
  Eigen::Matrix2d linear;
  linear << 30.0, 5.0, -4.0, 12.0;
  const Vector2d shift(100.0, -20.0);
  const Eigen::MatrixX2d image = (boundary * linear.transpose()).rowwise() + shift.transpose();
  for (int trial = 0; trial < 200; ++trial) {
    const Vector2d uv(unit(random), unit(random));
    const Eigen::RowVectorXd w = square_mean_value_weights(uv, 64);
    EXPECT_GE(w.minCoeff(), 0.0);
    EXPECT_NEAR(w.sum(), 1.0, 1e-12);
    EXPECT_LT((w * boundary - uv.transpose()).norm(), 1e-10);
    EXPECT_LT((w * image - (linear * uv + shift).transpose()).norm(), 1e-8);
  }
  // On an edge: the two neighbouring boundary points only.
  const Eigen::RowVectorXd edge = square_mean_value_weights(Vector2d(1.0, 0.51), 64);
  EXPECT_EQ((edge.array() > 0.0).count(), 2);
  EXPECT_LT((edge * boundary - Eigen::RowVector2d(1.0, 0.51)).norm(), 1e-12);
  const Eigen::RowVectorXd corner = square_mean_value_weights(Vector2d(0.0, 0.0), 64);
  EXPECT_LT((corner * boundary).norm(), 1e-12);
  EXPECT_THROW((void)square_mean_value_weights(Vector2d(1.2, 0.5), 64), InvalidInputError);
}

Eigen::MatrixX3d circle(int n, double radius, double phase, bool clockwise) {
  Eigen::MatrixX3d loop(n, 3);
  for (int i = 0; i < n; ++i) {
    const double a = phase + (clockwise ? -1.0 : 1.0) * 2.0 * std::numbers::pi * i / n;
    loop.row(i) << radius * std::cos(a), radius * std::sin(a), 5.0;
  }
  return loop;
}

TEST(ConsistentContour, ClockwiseLoopIsTurnedAndStartsOnTheReferenceSide) {
  const Eigen::MatrixX3d loop = circle(200, 10.0, 2.0, true);
  const Contour c = consistent_contour(loop, Vector3d::UnitZ(), Vector3d(0, 1, 0.3), 64);
  ASSERT_EQ(c.rows(), 64);
  // Point 0 on the +y side (the reference across the axis), at the radius.
  EXPECT_NEAR(c(0, 0), 0.0, 1e-9);
  EXPECT_NEAR(c(0, 1), 10.0, 0.01);
  // Counter-clockwise about +z: the next points turn toward -x.
  EXPECT_LT(c(1, 0), 0.0);
  // Equal steps (chords of a 200-gon resampled at 64 points).
  Eigen::VectorXd steps(64);
  for (int i = 0; i < 64; ++i) steps(i) = (c.row((i + 1) % 64) - c.row(i)).norm();
  EXPECT_LT(steps.maxCoeff() - steps.minCoeff(), 0.01);
  EXPECT_THROW((void)consistent_contour(loop, Vector3d::UnitZ(), Vector3d::UnitZ(), 64),
               InvalidInputError);
  EXPECT_THROW((void)consistent_contour(loop.topRows(2), Vector3d::UnitZ(), Vector3d::UnitX(), 64),
               InvalidInputError);
}

// An ellipse sampled at `count` equal angle steps from angle `start` (rad),
// centred on `centre`: its points are not at equal arc length, which does not
// matter for a pure shift of the start.
Contour ellipse(int count, double start, const Vector3d& centre) {
  Contour c(count, 3);
  for (int i = 0; i < count; ++i) {
    const double a = start + 2.0 * std::numbers::pi * i / count;
    c.row(i) = (centre + Vector3d(20.0 * std::cos(a), 8.0 * std::sin(a), 0.0)).transpose();
  }
  return c;
}

TEST(AlignStart, RecoversAWholeAndAFractionalShift) {
  constexpr int kCount = 64;
  const double step = 2.0 * std::numbers::pi / kCount;
  const Contour neighbour = ellipse(kCount, 0.0, Vector3d(0, 0, 0));
  // The same ellipse 5 mm higher and moved sideways, starting 7 steps later:
  // its start goes back 7 steps, whatever the offset of the centres.
  const Contour later = ellipse(kCount, 7.0 * step, Vector3d(3, -2, 5));
  const Contour aligned = align_start(later, neighbour);
  EXPECT_LT(
      (aligned.rowwise() - Eigen::RowVector3d(3, -2, 5) - neighbour).rowwise().norm().maxCoeff(),
      1e-9);
  // A start 3.4 steps later: moved back to within the chord of one step.
  const Contour fraction = align_start(ellipse(kCount, 3.4 * step, Vector3d::Zero()), neighbour);
  EXPECT_LT((fraction - neighbour).rowwise().norm().maxCoeff(), 0.3);
  EXPECT_LT((fraction.row(0) - neighbour.row(0)).norm(), 0.3);
  // Already aligned: unchanged, bit for bit.
  EXPECT_EQ(align_start(neighbour, neighbour), neighbour);
  EXPECT_THROW((void)align_start(neighbour, ellipse(32, 0.0, Vector3d::Zero())), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fibres

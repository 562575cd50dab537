// Kruger's constrained cubic spline: it passes through every point, follows
// the slope rules of the paper, reproduces a straight line, and on step-like
// monotone data stays monotone and inside the data range where the C2
// interpolating spline (SimmSpline) overshoots.

#include "core/fibres/constrained_spline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/opensim/opensim_function.h"

namespace mmm::fibres {
namespace {

TEST(ConstrainedSplineTest, PassesThroughEveryPoint) {
  const std::vector<double> x = {-3.0, -2.5, 0.0, 0.1, 4.0, 9.0, 9.5};
  const std::vector<double> y = {2.0, -1.0, 7.0, 7.5, 7.5, -4.0, 3.0};
  const ConstrainedSpline spline(x, y);
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(spline.evaluate(x[i]), y[i]) << i;  // the Hermite basis is exact at s = 0, 1
    EXPECT_NEAR(spline.derivative(x[i]), spline.slopes()[i], 1e-12) << i;
  }
}

TEST(ConstrainedSplineTest, SlopesFollowKruger) {
  // Secants 2 and 0.5: harmonic mean 2 * 2 * 0.5 / 2.5 = 0.8 in the middle,
  // ends 3/2 * 2 - 0.8 / 2 = 2.6 and 3/2 * 0.5 - 0.8 / 2 = 0.35.
  const ConstrainedSpline rising({0.0, 1.0, 3.0}, {0.0, 2.0, 3.0});
  EXPECT_NEAR(rising.slopes()[0], 2.6, 1e-15);
  EXPECT_NEAR(rising.slopes()[1], 0.8, 1e-15);
  EXPECT_NEAR(rising.slopes()[2], 0.35, 1e-15);
  // The secants change sign (1, then -1): zero slope at the turn, ends +-1.5.
  const ConstrainedSpline peak({0.0, 1.0, 2.0}, {0.0, 1.0, 0.0});
  EXPECT_EQ(peak.slopes()[1], 0.0);
  EXPECT_NEAR(peak.slopes()[0], 1.5, 1e-15);
  EXPECT_NEAR(peak.slopes()[2], -1.5, 1e-15);
  // ... and the curve does not rise above the peak point.
  for (int s = 0; s <= 200; ++s) EXPECT_LE(peak.evaluate(s / 100.0), 1.0) << s;
}

TEST(ConstrainedSplineTest, ReproducesAStraightLine) {
  const std::vector<double> x = {0.0, 0.3, 1.7, 2.0, 5.5, 6.0};  // uneven steps
  std::vector<double> y;
  y.reserve(x.size());
  for (const double v : x) y.push_back(3.0 * v - 2.0);
  const ConstrainedSpline spline(x, y);
  double worst = 0.0;
  for (int s = 0; s <= 600; ++s) {
    const double v = 6.0 * s / 600.0;
    worst = std::max(worst, std::abs(spline.evaluate(v) - (3.0 * v - 2.0)));
    EXPECT_NEAR(spline.derivative(v), 3.0, 1e-12) << v;
  }
  EXPECT_LT(worst, 1e-13);  // rounding only, values up to 16
  // Two points are the straight segment, also beyond it (linear extrapolation).
  const ConstrainedSpline segment({1.0, 3.0}, {5.0, 1.0});
  EXPECT_NEAR(segment.evaluate(2.0), 3.0, 1e-15);
  EXPECT_NEAR(segment.evaluate(4.0), -1.0, 1e-15);
  EXPECT_NEAR(segment.evaluate(0.0), 7.0, 1e-15);
}

TEST(ConstrainedSplineTest, StepDataNeitherOvershootsNorOscillates) {
  // A monotone step: flat, a steep rise over uneven steps, flat.
  const std::vector<double> x = {0.0, 1.0, 2.0, 3.0, 3.5, 5.0, 6.0, 7.0};
  const std::vector<double> y = {0.0, 0.0, 0.0, 0.1, 0.9, 1.0, 1.0, 1.0};
  const ConstrainedSpline spline(x, y);
  const opensim::SimmSpline c2(x, y);
  double low = 0.0;
  double high = 1.0;
  double c2_low = 0.0;
  double c2_high = 1.0;
  double previous = -std::numeric_limits<double>::infinity();
  for (int s = 0; s <= 7000; ++s) {
    const double v = 7.0 * s / 7000.0;
    const double value = spline.evaluate(v);
    EXPECT_GE(value, previous - 1e-15) << v;  // monotone up to rounding of the Hermite sum
    previous = value;
    low = std::min(low, value);
    high = std::max(high, value);
    c2_low = std::min(c2_low, c2.evaluate(v));
    c2_high = std::max(c2_high, c2.evaluate(v));
  }
  EXPECT_GE(low, -1e-15);  // within [0, 1] up to rounding
  EXPECT_LE(high, 1.0 + 1e-15);
  // The C2 spline swings past both plateaus (measured: down to -0.137 and up
  // to 1.276), so the contrast is real, not a rounding artefact.
  EXPECT_LT(c2_low, -0.1);
  EXPECT_GT(c2_high, 1.2);
}

TEST(ConstrainedSplineTest, EveryPieceStaysBetweenItsEndValues) {
  const std::vector<double> x = {0.0, 0.4, 1.0, 1.2, 3.0, 3.1, 5.0};
  const std::vector<double> y = {1.0, 4.0, -2.0, -2.0, 6.0, 5.0, 9.0};
  const ConstrainedSpline spline(x, y);
  for (std::size_t k = 0; k + 1 < x.size(); ++k) {
    const double lo = std::min(y[k], y[k + 1]);
    const double hi = std::max(y[k], y[k + 1]);
    for (int s = 0; s <= 100; ++s) {
      const double value = spline.evaluate(x[k] + (x[k + 1] - x[k]) * s / 100.0);
      EXPECT_GE(value, lo - 1e-12) << k << " " << s;  // rounding of the Hermite sum
      EXPECT_LE(value, hi + 1e-12) << k << " " << s;
    }
  }
}

TEST(ConstrainedSplineTest, BadInputIsRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(ConstrainedSpline({0.0, 1.0}, {0.0}), InvalidInputError);
  EXPECT_THROW(ConstrainedSpline({0.0}, {0.0}), InvalidInputError);
  EXPECT_THROW(ConstrainedSpline({}, {}), InvalidInputError);
  EXPECT_THROW(ConstrainedSpline({0.0, 1.0, 1.0}, {0.0, 1.0, 2.0}), InvalidInputError);
  EXPECT_THROW(ConstrainedSpline({0.0, 2.0, 1.0}, {0.0, 1.0, 2.0}), InvalidInputError);
  EXPECT_THROW(ConstrainedSpline({0.0, nan, 2.0}, {0.0, 1.0, 2.0}), InvalidInputError);
  EXPECT_THROW(ConstrainedSpline({0.0, 1.0, 2.0}, {0.0, inf, 2.0}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::fibres

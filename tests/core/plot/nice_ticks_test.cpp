#include "core/plot/nice_ticks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_helpers.h"

namespace mmm::plot {
namespace {

using ::testing::ElementsAre;

using test::kNaN;

TEST(NiceTicksTest, KnownRanges) {
  EXPECT_THAT(nice_ticks(0, 97), ElementsAre(0, 20, 40, 60, 80, 100));
  EXPECT_THAT(nice_ticks(0, 10), ElementsAre(0, 2, 4, 6, 8, 10));
  // k * m / 10^-e is the double nearest the decimal (3 * 0.2 would be
  // 0.6000000000000001), so the ticks compare equal to their literals.
  EXPECT_THAT(nice_ticks(0, 1), ElementsAre(0, 0.2, 0.4, 0.6, 0.8, 1));
  const std::vector<double> small = nice_ticks(-0.013, 0.021);
  const std::vector<double> expected = {-0.02, -0.01, 0, 0.01, 0.02, 0.03};
  ASSERT_EQ(small.size(), expected.size());
  for (std::size_t i = 0; i < small.size(); ++i) {
    EXPECT_NEAR(small[i], expected[i], 1e-15) << i;  // a few ulps of 0.01
  }
  EXPECT_EQ(small[2], 0.0);  // exactly zero, never 1e-18 or -0
  // A point is widened by 10 % of its value (1 at zero).
  EXPECT_THAT(nice_ticks(5, 5), ElementsAre(4.5, 4.75, 5, 5.25, 5.5));
  EXPECT_THAT(nice_ticks(0, 0), ElementsAre(-1, -0.5, 0, 0.5, 1));
}

TEST(NiceTicksTest, CoverTheRangeWithFourToEightNiceSteps) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> exponent(-12, 12);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    const double scale = std::pow(10.0, exponent(rng));
    double lo = unit(rng) * scale;
    double hi = unit(rng) * scale;
    if (lo > hi) std::swap(lo, hi);
    SCOPED_TRACE(testing::Message() << "[" << lo << ", " << hi << "]");
    const std::vector<double> ticks = nice_ticks(lo, hi);
    ASSERT_GE(ticks.size(), 4U);
    ASSERT_LE(ticks.size(), 8U);
    const double step = ticks[1] - ticks[0];
    // Covering, up to the rounding of the tick products (1e-9 of a step).
    EXPECT_LE(ticks.front(), lo + step * 1e-9);
    EXPECT_GE(ticks.back(), hi - step * 1e-9);
    // m x 10^k with m in {1, 2, 2.5, 5}.
    const double mantissa =
        step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));  // 0.0999... is a step of 0.1
    const bool nice = std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
                      std::abs(mantissa - 2.5) < 1e-9 || std::abs(mantissa - 5) < 1e-9;
    EXPECT_TRUE(nice) << "step " << step;
    for (std::size_t i = 1; i < ticks.size(); ++i) {
      EXPECT_NEAR(ticks[i] - ticks[i - 1], step, step * 1e-9);  // evenly spaced
    }
  }
}

TEST(NiceTicksTest, ExtremeRangesGiveFiniteTicks) {
  const double max = std::numeric_limits<double>::max();
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{
           {-max, max}, {0, max}, {max, max}, {0, 4.9e-324}, {1e-300, 1e-300}}) {
    const std::vector<double> ticks = nice_ticks(lo, hi);
    ASSERT_GE(ticks.size(), 2U);
    for (const double tick : ticks) EXPECT_TRUE(std::isfinite(tick));
  }
}

TEST(NiceTicksTest, RejectsBadArguments) {
  EXPECT_THROW(nice_ticks(kNaN, 1), InvalidInputError);
  EXPECT_THROW(nice_ticks(0, std::numeric_limits<double>::infinity()), InvalidInputError);
  EXPECT_THROW(nice_ticks(2, 1), InvalidInputError);
  EXPECT_THROW(nice_ticks(0, 1, 1), InvalidInputError);
  EXPECT_THROW(nice_ticks(0, 1, 51), InvalidInputError);
}

TEST(TickLabelsTest, NoTrailingZeroNoise) {
  EXPECT_THAT(tick_labels({0, 0.5, 1, 1.5}), ElementsAre("0", "0.5", "1", "1.5"));
  EXPECT_THAT(tick_labels({-20, -10, 0, 10}), ElementsAre("-20", "-10", "0", "10"));
  EXPECT_THAT(tick_labels({0, 0.25, 0.5, 0.75}), ElementsAre("0", "0.25", "0.5", "0.75"));
  EXPECT_THAT(tick_labels(nice_ticks(-0.013, 0.021)),
              ElementsAre("-0.02", "-0.01", "0", "0.01", "0.02", "0.03"));
  // 3 * 0.1 is 0.30000000000000004: the label is still "0.3".
  EXPECT_THAT(tick_labels({0.1, 0.2, 3 * 0.1}), ElementsAre("0.1", "0.2", "0.3"));
  EXPECT_THAT(tick_labels({999000, 999500, 1000000}),
              ElementsAre("9.99e+05", "9.995e+05", "1e+06"));
  EXPECT_THAT(tick_labels({0, 2e5, 4e5, 6e5, 8e5, 1e6}),
              ElementsAre("0", "2e+05", "4e+05", "6e+05", "8e+05", "1e+06"));
  EXPECT_THAT(tick_labels({1e-5, 2e-5, 3e-5}), ElementsAre("1e-05", "2e-05", "3e-05"));
  EXPECT_THAT(tick_labels({100000, 200000}), ElementsAre("100000", "200000"));
  EXPECT_THAT(tick_labels({}), ElementsAre());
}

}  // namespace
}  // namespace mmm::plot

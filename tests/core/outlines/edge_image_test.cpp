// Edge search on a radiograph: a straight step edge found where it is from
// either side; nothing found on a flat image or beyond the reach; a layer
// taken out of an image leaves the image without it, edges included.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/outlines/edge_image.h"

namespace mmm::outlines {
namespace {

// Bright (bone) left of x = 50, dark right of it.
image::GrayImage16 step_image() {
  image::GrayImage16 image(100, 100, 1000);
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 50; ++x) image.at(x, y) = 5000;
  }
  return image;
}

TEST(EdgeImageTest, AStepEdgeIsFoundFromEitherSide) {
  const EdgeImage edges(step_image(), 1.0, 0.0);
  for (const double start : {45.0, 48.0, 50.0, 52.0, 54.5}) {
    const auto edge = edges.edge_along({start, 50.0}, {1.0, 0.0}, 8.0, 1.0);
    ASSERT_TRUE(edge.has_value()) << start;
    // A step's steepest fall is at the step; the returned edge is moved out
    // by the square-root-profile shift (kSqrtEdgeShift sigma).
    EXPECT_NEAR(start + edge->offset_px, 50.0 + kSqrtEdgeShift, 0.05) << start;
  }
}

TEST(EdgeImageTest, NothingIsFoundOnAFlatImageOrBeyondTheReach) {
  const EdgeImage flat(image::GrayImage16(100, 100, 1000), 1.0);
  EXPECT_FALSE(flat.edge_along({50, 50}, {1, 0}, 8.0, 1.0).has_value());
  const EdgeImage edges(step_image(), 1.0);
  EXPECT_FALSE(edges.edge_along({30, 50}, {1, 0}, 8.0, 1.0).has_value());
  // The fall runs the other way: bright is outside.
  EXPECT_FALSE(edges.edge_along({50, 50}, {-1, 0}, 8.0, 1.0).has_value());
}

// A second bone (a bright square) over the step, taken out as a layer: the
// image is the step alone again, at every sample and in its edges.
TEST(EdgeImageTest, ALayerTakenOutLeavesTheImageWithoutIt) {
  const image::GrayImage16 step = step_image();
  image::GrayImage16 both = step;
  image::FloatImage square(20, 30);  // at (60, 40)
  for (int y = 0; y < square.height; ++y) {
    for (int x = 0; x < square.width; ++x) {
      square.at(x, y) = 3000.0F;
      both.at(60 + x, 40 + y) = static_cast<std::uint16_t>(both.at(60 + x, 40 + y) + 3000);
    }
  }
  const EdgeImage alone(step, 1.5, 0.0);
  const EdgeImage with_square(both, 1.5, 0.0);
  const EdgeImage without = with_square.without(square, {60, 40});
  double worst = 0.0;
  double worst_with = 0.0;
  for (double y = 0.5; y < 100; y += 1.25) {
    for (double x = 0.5; x < 100; x += 1.25) {
      worst = std::max(worst, std::abs(without.sample({x, y}) - alone.sample({x, y})));
      worst_with =
          std::max(worst_with, std::abs(with_square.sample({x, y}) - alone.sample({x, y})));
    }
  }
  EXPECT_GT(worst_with, 2900.0);
  EXPECT_LT(worst, 0.01);
  // The square's left edge (x = 60) is an edge of the image with it, not without.
  const auto inside = with_square.edge_along({65, 55}, {-1, 0}, 8.0, 100.0);
  ASSERT_TRUE(inside.has_value());
  EXPECT_NEAR(65.0 + (-1.0) * inside->offset_px, 60.0 - kSqrtEdgeShift * 1.5, 0.1);
  EXPECT_FALSE(without.edge_along({65, 55}, {-1, 0}, 8.0, 100.0).has_value());
  // The median gradient is the image's own.
  EXPECT_DOUBLE_EQ(without.median_gradient(), with_square.median_gradient());
}

TEST(EdgeImageTest, AnEmptyOrNonFiniteLayerOrASecondOneIsRejected) {
  const EdgeImage edges(step_image(), 1.0);
  EXPECT_THROW((void)edges.without(image::FloatImage(), {0, 0}), InvalidInputError);
  image::FloatImage bad(4, 4);
  bad.at(1, 2) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW((void)edges.without(bad, {0, 0}), InvalidInputError);
  const EdgeImage once = edges.without(image::FloatImage(4, 4, 1.0F), {10, 10});
  EXPECT_THROW((void)once.without(image::FloatImage(4, 4, 1.0F), {10, 10}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::outlines

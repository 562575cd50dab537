// Edge search on a radiograph: a straight step edge found where it is from
// either side; nothing found on a flat image or beyond the reach.

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace mmm::outlines

// A bone's share of a radiograph, rendered as a layer: a sphere's layer is
// its gain times the chord through it (2 r at the centre, nothing outside
// its outline), the same as a DRR of it, and a region reaching outside the
// image is clipped to it.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/image/drr.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/primitives.h"
#include "core/outlines/bone_layer.h"
#include "tests/support/noiseless_pair.h"

namespace mmm::outlines {
namespace {

using Eigen::Vector3d;

const Vector3d kBallCentre(600, 450, 500);
constexpr double kBallRadius = 15.0;
constexpr double kBallGain = 180.0;

mesh::IndexedMesh ball() {
  mesh::IndexedMesh surface = mesh::make_icosphere(5, kBallRadius);
  surface.V.rowwise() += kBallCentre.transpose();
  return surface;
}

TEST(BoneLayerTest, ASpheresLayerIsItsGainTimesItsChords) {
  const mesh::IndexedMesh surface = ball();
  const mesh::AabbTree tree(surface);
  const test::NoiselessPair pair = test::render_noiseless_pair(surface, kBallCentre, 80);
  for (const image::RadiographView& view : pair.views) {
    const PixelRegion everything{0, 0, view.width, view.height};
    const BoneLayer layer = render_bone_layer({{&tree, kBallGain}}, view, everything);
    ASSERT_EQ(layer.values.width, view.width);
    const Eigen::Vector2d centre = image::project(view, kBallCentre);
    const int cx = static_cast<int>(std::floor(centre.x()));
    const int cy = static_cast<int>(std::floor(centre.y()));
    // Through the middle: the diameter (the icosphere's chord is within
    // 0.1 % of it), times the gain.
    EXPECT_NEAR(layer.values.at(cx, cy), kBallGain * 2 * kBallRadius,
                0.005 * kBallGain * 2 * kBallRadius);
    // Its outline covers pi r^2.
    const double radius_px = kBallRadius / view.pixel_spacing_mm;  // the sphere is at the isocentre
    EXPECT_NEAR(layer.pixels_crossed, std::numbers::pi * radius_px * radius_px,
                0.02 * std::numbers::pi * radius_px * radius_px);
    // The same as a DRR of the sphere at attenuation `kBallGain`, pixel by pixel.
    const std::array<image::AttenuatingMesh, 1> meshes = {image::AttenuatingMesh{&tree, kBallGain}};
    const image::FloatImage drr = image::render_drr(view, meshes);
    double worst = 0.0;
    for (int y = 0; y < view.height; ++y) {
      for (int x = 0; x < view.width; ++x) {
        worst =
            std::max(worst, std::abs(static_cast<double>(layer.values.at(x, y)) - drr.at(x, y)));
      }
    }
    EXPECT_LT(worst, 0.01 * kBallGain);
  }
}

TEST(BoneLayerTest, ARegionReachingOutsideTheImageIsClipped) {
  const mesh::IndexedMesh surface = ball();
  const mesh::AabbTree tree(surface);
  const test::NoiselessPair pair = test::render_noiseless_pair(surface, kBallCentre, 80);
  const image::RadiographView& view = pair.views[0];
  const BoneLayer layer = render_bone_layer({{&tree, kBallGain}}, view,
                                            {-20, -30, view.width / 2 + 20, view.height + 60});
  EXPECT_EQ(layer.origin, Eigen::Vector2i(0, 0));
  EXPECT_EQ(layer.values.width, view.width / 2);
  EXPECT_EQ(layer.values.height, view.height);
  // Half the sphere's outline, give or take its middle column.
  const BoneLayer whole =
      render_bone_layer({{&tree, kBallGain}}, view, {0, 0, view.width, view.height});
  EXPECT_NEAR(layer.pixels_crossed, 0.5 * whole.pixels_crossed, 0.05 * whole.pixels_crossed);
  // No region at all: an empty layer.
  EXPECT_TRUE(
      render_bone_layer({{&tree, kBallGain}}, view, {view.width + 5, 0, 10, 10}).values.empty());
}

TEST(BoneLayerTest, ABoneWithoutSurfaceOrGainIsRejected) {
  const mesh::IndexedMesh surface = ball();
  const mesh::AabbTree tree(surface);
  const test::NoiselessPair pair = test::render_noiseless_pair(surface, kBallCentre, 80);
  const PixelRegion region{0, 0, 10, 10};
  EXPECT_THROW((void)render_bone_layer({{nullptr, kBallGain}}, pair.views[0], region),
               InvalidInputError);
  EXPECT_THROW((void)render_bone_layer({{&tree, std::numeric_limits<double>::quiet_NaN()}},
                                       pair.views[0], region),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::outlines

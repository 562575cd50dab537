#include "core/image/mesh_render.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"

namespace mmm::image {
namespace {

using ::testing::HasSubstr;

constexpr Rgb8 kRed{220, 30, 30};
constexpr Rgb8 kBlue{30, 30, 220};
constexpr Rgb8 kWhite{255, 255, 255};

int count_not(const RgbImage8& image, Rgb8 colour) {
  int count = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) count += get_rgb(image, x, y) == colour ? 0 : 1;
  }
  return count;
}

// A sphere seen front-on covers the disc of radius R s pixels. The icosphere's
// silhouette is an inscribed polygon, short of the circle by at most the gap
// (test::icosphere_gap, 0.05 mm here): an area deficit of at most 2 gap / R =
// 0.2 %. Pixel centres sample the disc's edge: the count's error is of the
// order of the square root of the perimeter (~25 px of 31416). 1 % covers both.
TEST(MeshRenderTest, SphereCoversPiRSquaredPixels) {
  constexpr double kRadius = 50.0;
  constexpr double kScale = 2.0;  // pixels per mm: a disc of radius 100 px
  const mesh::IndexedMesh sphere = mesh::make_icosphere(4, kRadius, {10, -20, 30});
  ASSERT_LT(test::icosphere_gap(sphere, kRadius, {10, -20, 30}), 0.1);
  const std::vector<RenderItem> items = {{&sphere, kRed}};
  RenderOptions options;
  options.pixels_per_mm = kScale;
  const RgbImage8 image = render_meshes(items, options);
  // 100 mm at 2 px/mm plus two 10 px margins.
  EXPECT_EQ(image.width, 220);
  EXPECT_EQ(image.height, 220);
  const double disc = std::numbers::pi * std::pow(kRadius * kScale, 2);
  EXPECT_NEAR(count_not(image, kWhite) / disc, 1.0, 0.01);
  // The outline is drawn over the sphere's own border pixels, not around it.
  options.outline = false;
  EXPECT_EQ(count_not(render_meshes(items, options), kWhite), count_not(image, kWhite));
}

TEST(MeshRenderTest, FacingSurfaceGetsTheFullColourAndTheRimIsDarker) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(4, 50.0);
  const std::vector<RenderItem> items = {{&sphere, kRed}};
  RenderOptions options;
  options.pixels_per_mm = 2.0;
  options.outline = false;
  const RgbImage8 image = render_meshes(items, options);
  // At the centre the interpolated normal faces the camera to within the
  // tessellation (cos ~ 1 - 1e-4): full colour, +-1 for rounding.
  const Rgb8 centre = get_rgb(image, 110, 110);
  EXPECT_NEAR(centre.r, kRed.r, 1);
  EXPECT_NEAR(centre.b, kRed.b, 1);
  // Two pixels inside the silhouette the surface is nearly edge-on: close
  // to the ambient share (0.3) of the colour.
  const Rgb8 rim = get_rgb(image, 12, 110);
  EXPECT_LT(rim.r, 0.6 * kRed.r);
  EXPECT_GE(rim.r, 0.3 * kRed.r - 1);
}

TEST(MeshRenderTest, NearerMeshOccludesFartherOne) {
  // Both spheres on the line of sight of the front view (looking along -y):
  // the anterior one (y = +100) is nearer the camera.
  const mesh::IndexedMesh front = mesh::make_icosphere(3, 30.0, {0, 100, 0});
  const mesh::IndexedMesh back = mesh::make_icosphere(3, 50.0, {0, -100, 0});
  RenderOptions options;
  options.pixels_per_mm = 1.0;
  for (const bool front_first : {true, false}) {
    std::vector<RenderItem> items = {{&front, kRed}, {&back, kBlue}};
    if (!front_first) std::swap(items[0], items[1]);
    const RgbImage8 image = render_meshes(items, options);
    const int c = image.width / 2;
    const Rgb8 middle = get_rgb(image, c, c);
    EXPECT_GT(middle.r, 150) << "front first: " << front_first;  // red, nearly full
    EXPECT_LT(middle.b, 60);
    // Outside the small sphere but inside the big one: blue.
    const Rgb8 beside = get_rgb(image, c + 40, c);
    EXPECT_GT(beside.b, beside.r);
    // Walking right from the centre: red, then one outline pixel on the red
    // sphere's rim (the nearer side of the contour, pixel centre 29.5 mm from
    // the axis, inside the 30 mm silhouette), then blue.
    EXPECT_GT(get_rgb(image, c + 28, c).r, 100);
    EXPECT_EQ(get_rgb(image, c + 29, c), options.outline_colour);
    EXPECT_GT(get_rgb(image, c + 30, c).b, 100);
  }
}

TEST(MeshRenderTest, FrontViewShowsTheSubjectsRightOnTheLeft) {
  const mesh::IndexedMesh right = mesh::make_icosphere(2, 20.0, {100, 0, 0});
  const mesh::IndexedMesh left = mesh::make_icosphere(2, 20.0, {-100, 0, 50});
  const std::vector<RenderItem> items = {{&right, kRed}, {&left, kBlue}};
  RenderOptions options;
  options.image_width = 300;
  const RgbImage8 front = render_meshes(items, options);
  EXPECT_EQ(front.width, 300);  // fitted
  const auto at = [](const RgbImage8& image, double fx, double fy) {
    return get_rgb(image, static_cast<int>(fx * image.width), static_cast<int>(fy * image.height));
  };
  // Subject's right (+x) on the image left; the left sphere is higher (+z).
  EXPECT_GT(at(front, 0.1, 0.7).r, 150);
  EXPECT_GT(at(front, 0.9, 0.3).b, 150);
  // Seen from the subject's right, +x is the nearer: the red sphere hides
  // the blue one where they overlap (both at y = 0).
  options.view_direction = {-1, 0, 0};
  const RgbImage8 side = render_meshes(items, options);
  EXPECT_GT(at(side, 0.5, 0.75).r, 150);
}

TEST(MeshRenderTest, SideBySidePlacesImagesLeftToRight) {
  RgbImage8 a(3, 2);
  RgbImage8 b(2, 4);
  set_rgb(a, 2, 1, kRed);
  set_rgb(b, 0, 3, kBlue);
  const std::vector<RgbImage8> images = {a, b};
  SideBySideOptions options;
  options.gap_px = 1;
  options.background = {1, 2, 3};
  const RgbImage8 both = side_by_side(images, options);
  EXPECT_EQ(both.width, 6);
  EXPECT_EQ(both.height, 4);
  EXPECT_EQ(get_rgb(both, 2, 1), kRed);
  EXPECT_EQ(get_rgb(both, 3, 0), options.background);  // the gap
  EXPECT_EQ(get_rgb(both, 0, 3), options.background);  // below the shorter image
  EXPECT_EQ(get_rgb(both, 4, 3), kBlue);
  EXPECT_EQ(get_rgb(both, 0, 0), (Rgb8{0, 0, 0}));  // a's own pixels
}

TEST(MeshRenderTest, BadInputIsRejected) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(1, 10.0);
  const std::vector<RenderItem> good = {{&sphere, kRed}};
  const std::vector<RenderItem> null_mesh = {{nullptr, kRed}};
  EXPECT_THAT([&] { (void)render_meshes(null_mesh); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("item 0 has no mesh")));
  const mesh::IndexedMesh empty;
  const std::vector<RenderItem> nothing = {{&empty, kRed}};
  EXPECT_THAT([&] { (void)render_meshes(nothing); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("no face")));
  RenderOptions parallel;
  parallel.up = {0, 2, 0};
  EXPECT_THAT([&] { (void)render_meshes(good, parallel); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("parallel")));
  RenderOptions huge;
  huge.pixels_per_mm = 1e4;
  EXPECT_THAT([&] { (void)render_meshes(good, huge); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("limit")));
  RenderOptions ambient;
  ambient.ambient = 1.5;
  EXPECT_THROW((void)render_meshes(good, ambient), InvalidInputError);
  EXPECT_THROW((void)side_by_side(std::vector<RgbImage8>{}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::image

#include "core/image/outline_overlay.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/errors.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"
#include "tests/support/test_data.h"

namespace mmm::image {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr Rgb8 kOutlineRed{230, 40, 40};
constexpr Rgb8 kOutlineBlue{40, 90, 240};
constexpr Rgb8 kOutlineYellow{250, 230, 20};

// A line of width 1.5 px (the default) reaches pixel centres up to
// 1.5 / 2 + 0.5 = 1.25 px from it (the anti-aliasing ramp).
constexpr double kReach = 1.25;

// Two views of a 200 x 200 mm field around the origin (872 x 872 pixels of
// 0.229 mm at the isocentre): small enough for quick tests.
std::array<RadiographView, 2> small_overlay_views() {
  BiplanarOptions options;
  options.field_width_mm = 200;
  options.field_height_mm = 200;
  return make_biplanar_views(options);
}

// A radiograph that is not flat (so that "untouched" means something): a
// ramp in both directions, values 20 x + 30 y < 65536.
GrayImage16 ramp(const RadiographView& view) {
  GrayImage16 image(view.width, view.height);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      image.at(x, y) = static_cast<std::uint16_t>(20 * x + 30 * y);
    }
  }
  return image;
}

// Explicit window [0, 50000] and no legend: every untouched pixel has a
// grey value known in advance (expected_grey).
OverlayOptions plain_options() {
  OverlayOptions options;
  options.window_low = 0;
  options.window_high = 50000;
  options.legend = false;
  return options;
}

Rgb8 expected_grey(const GrayImage16& radiograph, int x, int y) {
  const double t = std::clamp(radiograph.at(x, y) / 50000.0, 0.0, 1.0);
  const auto g = static_cast<std::uint8_t>(std::lround(t * 255.0));
  return {g, g, g};
}

// Pixel centres whose colour differs from the windowed radiograph.
std::vector<Eigen::Vector2d> drawn_pixels(const RgbImage8& image, const GrayImage16& radiograph) {
  std::vector<Eigen::Vector2d> drawn;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (get_rgb(image, x, y) != expected_grey(radiograph, x, y)) {
        drawn.emplace_back(x + 0.5, y + 0.5);
      }
    }
  }
  return drawn;
}

// Projections of points of the circle where the tangent cone from the
// source touches the sphere (centre c, radius r): the plane of the circle is
// r^2 / D from c toward the source (D = |c - source|), its radius
// r sqrt(1 - r^2 / D^2).
std::vector<Eigen::Vector2d> projected_tangent_circle(const RadiographView& view,
                                                      const Eigen::Vector3d& c, double r) {
  const Eigen::Vector3d axis = c - view.source_mm;
  const double distance = axis.norm();
  const Eigen::Vector3d d = axis / distance;
  const Eigen::Vector3d e1 = d.unitOrthogonal();
  const Eigen::Vector3d e2 = d.cross(e1);
  const Eigen::Vector3d centre = c - (r * r / distance) * d;
  const double radius = r * std::sqrt(1 - r * r / (distance * distance));
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k < 360; ++k) {
    const double angle = k * std::numbers::pi / 180;
    points.push_back(
        project(view, centre + radius * (std::cos(angle) * e1 + std::sin(angle) * e2)));
  }
  return points;
}

TEST(OutlineOverlayTest, SphereAtTheIsocentreIsOutlinedByItsProjectedTangentCircle) {
  constexpr double kRadius = 50.0;  // mm: about 220 px in the image
  // 20480 faces: silhouette vertices lie within one edge (0.019 rad) of the
  // tangent circle, so they project at most 220 px * 0.019^2 / 2 = 0.04 px
  // inside it; chords sag by less still.
  const mesh::IndexedMesh sphere = mesh::make_icosphere(5, kRadius);
  const std::vector<OutlineItem> items = {{"sphere", &sphere, kOutlineRed}};
  for (const RadiographView& view : small_overlay_views()) {
    SCOPED_TRACE(view.name);
    const GrayImage16 radiograph = ramp(view);
    const RgbImage8 image = outline_overlay(view, radiograph, items, plain_options());
    ASSERT_EQ(image.width, view.width);
    ASSERT_EQ(image.height, view.height);
    // At the isocentre the cone is a right circular one about the central
    // ray: its projection is a circle about the image centre.
    const Eigen::Vector2d centre(view.width / 2.0, view.height / 2.0);
    const std::vector<Eigen::Vector2d> tangent = projected_tangent_circle(view, {0, 0, 0}, kRadius);
    const double radius = (tangent.front() - centre).norm();
    for (const Eigen::Vector2d& p : tangent) EXPECT_NEAR((p - centre).norm(), radius, 1e-6);
    EXPECT_NEAR(radius, kRadius / view.pixel_spacing_mm, 0.5);  // sanity: ~218 px
    // Every drawn pixel lies on the circle: within the line's reach plus the
    // 0.04 px of tessellation, rounded up to 1.5 px.
    const std::vector<Eigen::Vector2d> drawn = drawn_pixels(image, radiograph);
    double worst = 0;
    for (const Eigen::Vector2d& p : drawn) {
      worst = std::max(worst, std::abs((p - centre).norm() - radius));
    }
    EXPECT_LE(worst, 1.5);
    // ... and the circle is closed: the pixel under each tangent point (its
    // centre within 0.71 px of the circle, so coverage >= 0.5) is drawn.
    for (const Eigen::Vector2d& p : tangent) {
      const int x = static_cast<int>(std::floor(p.x()));
      const int y = static_cast<int>(std::floor(p.y()));
      EXPECT_NE(get_rgb(image, x, y), expected_grey(radiograph, x, y)) << p.transpose();
    }
    // A 1.5 px wide ring of radius 218 px covers about 2 pi 218 * 2.5 pixels
    // (line plus ramp): a loose check that nothing is drawn twice over.
    EXPECT_GT(drawn.size(), 2 * std::numbers::pi * radius * 1.5);
    EXPECT_LT(drawn.size(), 2 * std::numbers::pi * radius * 3.0);
  }
}

// Distance from p to the boundary of the axis-aligned rectangle [lo, hi].
double distance_to_rectangle(const Eigen::Vector2d& p, const Eigen::Vector2d& lo,
                             const Eigen::Vector2d& hi) {
  const Eigen::Vector2d outside = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  if (outside.squaredNorm() > 0) return outside.norm();
  return std::min({p.x() - lo.x(), hi.x() - p.x(), p.y() - lo.y(), hi.y() - p.y()});
}

TEST(OutlineOverlayTest, BoxSeenFrontallyIsOutlinedByItsNearFaceRectangle) {
  // Seen from the frontal source (in front, +y) the near face y = +30
  // projects larger than the far face y = -30 (magnification 1300/1270 vs
  // 1300/1330): the silhouette is the near face's rectangle, its edges
  // shared by the front-facing near face and the back-facing sides.
  const mesh::IndexedMesh box = mesh::make_box({-40, -30, -60}, {40, 30, 60});
  const std::vector<OutlineItem> items = {{"box", &box, kOutlineBlue}};
  const RadiographView view = small_overlay_views()[0];
  const GrayImage16 radiograph = ramp(view);
  const RgbImage8 image = outline_overlay(view, radiograph, items, plain_options());
  const Eigen::Vector2d a = project(view, {-40, 30, -60});
  const Eigen::Vector2d b = project(view, {40, 30, 60});
  const Eigen::Vector2d lo = a.cwiseMin(b);
  const Eigen::Vector2d hi = a.cwiseMax(b);
  // Axis-aligned: the other two corners share these coordinates.
  EXPECT_NEAR(project(view, {-40, 30, 60}).x(), a.x(), 1e-9);
  EXPECT_NEAR(project(view, {40, 30, -60}).y(), a.y(), 1e-9);
  const std::vector<Eigen::Vector2d> drawn = drawn_pixels(image, radiograph);
  ASSERT_FALSE(drawn.empty());
  for (const Eigen::Vector2d& p : drawn) {
    // The line's reach, plus 1e-9 for rounding of the projections.
    ASSERT_LE(distance_to_rectangle(p, lo, hi), kReach + 1e-9) << p.transpose();
  }
  // Each side is drawn all along (sampled every 5 px), the far face's
  // rectangle (8 px inside) and the faces' diagonals are not (above).
  const auto is_drawn = [&](double u, double v) {
    const int x = static_cast<int>(std::floor(u));
    const int y = static_cast<int>(std::floor(v));
    return get_rgb(image, x, y) != expected_grey(radiograph, x, y);
  };
  for (double u = lo.x() + 2; u < hi.x() - 2; u += 5) {
    EXPECT_TRUE(is_drawn(u, lo.y()) && is_drawn(u, hi.y())) << u;
  }
  for (double v = lo.y() + 2; v < hi.y() - 2; v += 5) {
    EXPECT_TRUE(is_drawn(lo.x(), v) && is_drawn(hi.x(), v)) << v;
  }
}

TEST(OutlineOverlayTest, OpenSurfaceIsOutlinedAlongItsBoundaryOnly) {
  // A 100 x 100 mm jittered grid in the plane y = 0, facing the frontal
  // source: every inner edge joins two front-facing triangles; only the
  // boundary square is drawn.
  mesh::IndexedMesh grid = test::make_jittered_grid(11, 10.0, 0.5, 7);
  const Eigen::MatrixX3d planar = grid.V;
  grid.V.col(0) = planar.col(0).array() - 50;  // x in [-50, 50]
  grid.V.col(1).setZero();                     // y = 0
  grid.V.col(2) = planar.col(1).array() - 50;  // z in [-50, 50]
  const std::vector<OutlineItem> items = {{"grid", &grid, kOutlineYellow}};
  const RadiographView view = small_overlay_views()[0];
  const GrayImage16 radiograph = ramp(view);
  const RgbImage8 image = outline_overlay(view, radiograph, items, plain_options());
  const Eigen::Vector2d a = project(view, {-50, 0, -50});
  const Eigen::Vector2d b = project(view, {50, 0, 50});
  const std::vector<Eigen::Vector2d> drawn = drawn_pixels(image, radiograph);
  ASSERT_FALSE(drawn.empty());
  for (const Eigen::Vector2d& p : drawn) {
    ASSERT_LE(distance_to_rectangle(p, a.cwiseMin(b), a.cwiseMax(b)), kReach + 1e-9);
  }
}

TEST(OutlineOverlayTest, SmallSilhouetteLoopsAreDroppedUnlessAsked) {
  // One face of a sphere flipped, on the side facing the frontal source: it
  // alone is back-facing among front-facing neighbours, so its 3 edges form
  // a closed silhouette loop of their own (the noise a coarse mesh makes
  // where faces turn edge-on).
  const mesh::IndexedMesh sphere = mesh::make_icosphere(3, 50.0);
  mesh::IndexedMesh flipped = sphere;
  Eigen::Index nearest = 0;
  for (Eigen::Index f = 0; f < sphere.F.rows(); ++f) {
    const auto y = [&](Eigen::Index face) {
      return sphere.V(sphere.F(face, 0), 1) + sphere.V(sphere.F(face, 1), 1) +
             sphere.V(sphere.F(face, 2), 1);
    };
    if (y(f) > y(nearest)) nearest = f;
  }
  std::swap(flipped.F(nearest, 1), flipped.F(nearest, 2));
  const RadiographView view = small_overlay_views()[0];
  const GrayImage16 radiograph = ramp(view);
  OverlayOptions options = plain_options();
  const std::vector<OutlineItem> clean = {{"sphere", &sphere, kOutlineRed}};
  const std::vector<OutlineItem> noisy = {{"sphere", &flipped, kOutlineRed}};
  // Dropped by default (fewer than 8 edges): the picture is the clean one.
  EXPECT_EQ(outline_overlay(view, radiograph, noisy, options).pixels,
            outline_overlay(view, radiograph, clean, options).pixels);
  // Kept with min_contour_edges 3: a small triangle drawn at the face's
  // projection, the centre of the image.
  options.min_contour_edges = 3;
  const RgbImage8 image = outline_overlay(view, radiograph, noisy, options);
  const Eigen::Vector2d centre = project(view, {0, 50, 0});
  int near_centre = 0;
  for (const Eigen::Vector2d& p : drawn_pixels(image, radiograph)) {
    near_centre += (p - centre).norm() < 40 ? 1 : 0;  // the face spans ~30 px
  }
  EXPECT_GT(near_centre, 20);
  options.min_contour_edges = 4;
  EXPECT_EQ(outline_overlay(view, radiograph, noisy, options).pixels,
            outline_overlay(view, radiograph, clean, options).pixels);
  // A mesh's largest piece is always drawn: a lone triangle's 3 edges.
  mesh::IndexedMesh triangle;
  triangle.V.resize(3, 3);
  triangle.V << -30, 0, -30, 30, 0, -30, 0, 0, 30;
  triangle.F.resize(1, 3);
  triangle.F << 0, 1, 2;
  const std::vector<OutlineItem> lone = {{"triangle", &triangle, kOutlineRed}};
  EXPECT_GT(
      drawn_pixels(outline_overlay(view, radiograph, lone, plain_options()), radiograph).size(),
      500U);  // three sides of 260 px or more
}

TEST(OutlineOverlayTest, ItemsAndMarkersAreDrawnInTheirColours) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(4, 30.0, {-50, 0, 0});
  const mesh::IndexedMesh box = mesh::make_box({30, -20, -20}, {80, 20, 20});
  const std::vector<OutlineItem> items = {{"sphere", &sphere, kOutlineRed},
                                          {"box", &box, kOutlineBlue}};
  const RadiographView view = small_overlay_views()[0];
  const GrayImage16 flat(view.width, view.height, 1000);  // every pixel black
  OverlayOptions options;
  options.legend = false;
  options.line_width_px = 3.0;  // full coverage within 1 px of a line
  options.points = {{{0, 0, 60}, kOutlineYellow, PointMarker::kCross},
                    {{0, 0, -60}, kOutlineYellow, PointMarker::kCircle}};
  const RgbImage8 image = outline_overlay(view, flat, items, options);
  std::map<std::array<int, 3>, int> histogram;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Rgb8 c = get_rgb(image, x, y);
      ++histogram[{c.r, c.g, c.b}];
    }
  }
  // A flat radiograph has its 1st and 99th percentiles equal: windowed
  // [v, v + 1], so it is black.
  EXPECT_GT((histogram[{0, 0, 0}]), image.width * image.height / 2);
  // Hundreds of pixels exactly in each colour (lines of 3 px along
  // perimeters of several hundred px).
  EXPECT_GT((histogram[{kOutlineRed.r, kOutlineRed.g, kOutlineRed.b}]), 500);
  EXPECT_GT((histogram[{kOutlineBlue.r, kOutlineBlue.g, kOutlineBlue.b}]), 500);
  EXPECT_GT((histogram[{kOutlineYellow.r, kOutlineYellow.g, kOutlineYellow.b}]), 40);
  // Every other pixel is a blend of black with one of the colours: its
  // channels are the colour's scaled by one coverage, taken from the
  // colour's strongest channel (+-1.5 for the rounding of both).
  for (const auto& [c, count] : histogram) {
    if (c == std::array<int, 3>{0, 0, 0}) continue;
    bool blend = false;
    for (const Rgb8 colour : {kOutlineRed, kOutlineBlue, kOutlineYellow}) {
      const std::array<double, 3> target = {static_cast<double>(colour.r),
                                            static_cast<double>(colour.g),
                                            static_cast<double>(colour.b)};
      const auto strongest =
          static_cast<std::size_t>(std::distance(target.begin(), std::ranges::max_element(target)));
      const double a = c[strongest] / target[strongest];
      bool all = true;
      for (std::size_t k = 0; k < 3; ++k) all = all && std::abs(a * target[k] - c[k]) <= 1.5;
      blend = blend || all;
    }
    EXPECT_TRUE(blend) << c[0] << " " << c[1] << " " << c[2];
  }
  // The cross: its centre and arms drawn, its diagonal not; the ring: the
  // circle drawn, its centre not.
  const Eigen::Vector2d cross = project(view, {0, 0, 60});
  const Eigen::Vector2d ring = project(view, {0, 0, -60});
  const auto colour_at = [&](const Eigen::Vector2d& p) {
    return get_rgb(image, static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())));
  };
  const double r = options.marker_radius_px;
  EXPECT_EQ(colour_at(cross), kOutlineYellow);
  EXPECT_EQ(colour_at(cross + Eigen::Vector2d(r - 1, 0)), kOutlineYellow);
  EXPECT_EQ(colour_at(cross + Eigen::Vector2d(0, 1 - r)), kOutlineYellow);
  EXPECT_EQ(colour_at(cross + Eigen::Vector2d(r / 2, r / 2)), (Rgb8{0, 0, 0}));
  EXPECT_EQ(colour_at(ring + Eigen::Vector2d(r, 0)), kOutlineYellow);
  EXPECT_EQ(colour_at(ring + Eigen::Vector2d(0, -r)), kOutlineYellow);
  EXPECT_EQ(colour_at(ring), (Rgb8{0, 0, 0}));
}

TEST(OutlineOverlayTest, LegendIsAColumnOfSwatchesInTheItemsOrder) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(2, 10.0);
  const std::vector<OutlineItem> items = {
      {"a", &sphere, kOutlineRed}, {"b", &sphere, kOutlineBlue}, {"c", &sphere, kOutlineYellow}};
  const RadiographView view = small_overlay_views()[0];
  OverlayOptions options = plain_options();
  options.legend = true;
  const RgbImage8 image = outline_overlay(view, ramp(view), items, options);
  // Swatches of 14 px every 18 px from (8, 8), with a black border.
  EXPECT_EQ(get_rgb(image, 15, 15), kOutlineRed);
  EXPECT_EQ(get_rgb(image, 15, 15 + 18), kOutlineBlue);
  EXPECT_EQ(get_rgb(image, 15, 15 + 36), kOutlineYellow);
  EXPECT_EQ(get_rgb(image, 8, 15), (Rgb8{0, 0, 0}));
  EXPECT_EQ(get_rgb(image, 15, 8 + 36 + 13), (Rgb8{0, 0, 0}));
}

TEST(OutlineOverlayTest, DefaultWindowSpansThe1stTo99thPercentile) {
  // 100 x 100 pixels holding 0 ... 9999 once each: the 1st percentile is 99
  // (100 values <= it), the 99th 9899.
  BiplanarOptions geometry;
  const double spacing = geometry.detector_pixel_pitch_mm * geometry.source_to_isocentre_mm /
                         geometry.source_to_detector_mm;
  geometry.field_width_mm = 100 * spacing;
  geometry.field_height_mm = 100 * spacing;
  const RadiographView view = make_biplanar_views(geometry)[0];
  ASSERT_EQ(view.width, 100);
  ASSERT_EQ(view.height, 100);
  GrayImage16 radiograph(100, 100);
  for (int i = 0; i < 10000; ++i) {
    radiograph.pixels[static_cast<std::size_t>(i)] = static_cast<std::uint16_t>(i);
  }
  OverlayOptions options;
  options.legend = false;
  // No item: the windowed radiograph alone.
  const RgbImage8 image = outline_overlay(view, radiograph, {}, options);
  for (int i = 0; i < 10000; ++i) {
    const double t = std::clamp((i - 99.0) / (9899.0 - 99.0), 0.0, 1.0);
    const auto g = static_cast<std::uint8_t>(std::lround(255 * t));
    ASSERT_EQ(get_rgb(image, i % 100, i / 100), (Rgb8{g, g, g})) << i;
  }
  // Overridden: the window given.
  options.window_low = 0;
  options.window_high = 10000;
  EXPECT_EQ(get_rgb(outline_overlay(view, radiograph, {}, options), 0, 50).r, 128);  // 5000
}

// The pair as a study holds it, from two ramps.
RadiographPair ramp_pair(const test::ScratchDir& dir) {
  std::vector<RadiographFile> files;
  std::map<std::string, std::string> png;
  for (const RadiographView& view : small_overlay_views()) {
    write_png(ramp(view), dir / (view.name + ".png"));
    png[view.name] = test::read_text(dir / (view.name + ".png"));
    files.push_back({view, view.name + ".png"});
  }
  return make_radiograph_pair(files, png, dir.path());
}

TEST(OutlineOverlayTest, PairIsBothViewsSideBySideScaledDownToMaxWidth) {
  const test::ScratchDir dir("outline_overlay_pair");
  const RadiographPair pair = ramp_pair(dir);
  const std::array<RadiographView, 2> views = small_overlay_views();
  constexpr double kRadius = 50.0;
  const mesh::IndexedMesh sphere = mesh::make_icosphere(5, kRadius);
  const std::vector<OutlineItem> items = {{"sphere", &sphere, kOutlineRed}};
  OverlayOptions options = plain_options();
  const RgbImage8 full = outline_overlay_pair(pair, items, options);
  EXPECT_EQ(full.width, views[0].width + 10 + views[1].width);
  EXPECT_EQ(full.height, views[0].height);
  // The left half is exactly the frontal overlay.
  const RgbImage8 frontal = outline_overlay(views[0], ramp(views[0]), items, options);
  for (int y = 0; y < full.height; y += 7) {
    for (int x = 0; x < views[0].width; x += 3) {
      ASSERT_EQ(get_rgb(full, x, y), get_rgb(frontal, x, y)) << x << " " << y;
    }
  }
  // Scaled to 800 px: the 790 px left after the gap are shared by the two
  // 872 px views (395 px each) and the circle shrinks with them.
  options.max_width = 800;
  const RgbImage8 half = outline_overlay_pair(pair, items, options);
  EXPECT_LE(half.width, 800);
  const double scale = (800.0 - 10.0) / (2.0 * views[0].width);
  const int width = static_cast<int>(std::floor(views[0].width * scale));
  EXPECT_EQ(half.width, 2 * width + 10);
  const double radius = (project(views[0], {0, 0, kRadius}) - project(views[0], {0, 0, 0})).norm() *
                        width / views[0].width;
  const Eigen::Vector2d centre(width / 2.0, half.height / 2.0);
  // Pure red only on the circle (blends of red with grey are also drawn;
  // pure red needs coverage 1, within 0.25 px of the line).
  int red = 0;
  for (int y = 0; y < half.height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (get_rgb(half, x, y) != kOutlineRed) continue;
      ++red;
      // Tangent-point radius vs the equator point's: < 0.2 px at this
      // size; the resampled grid rounds the height by up to 0.5 px (0.3 px
      // at the centre); the line's full-coverage core is 0.25 px.
      EXPECT_NEAR((Eigen::Vector2d(x + 0.5, y + 0.5) - centre).norm(), radius, 1.0);
    }
  }
  EXPECT_GT(red, 100);
}

TEST(OutlineOverlayTest, BadInputIsRejectedWithItsName) {
  const RadiographView view = small_overlay_views()[0];
  const GrayImage16 radiograph = ramp(view);
  const mesh::IndexedMesh sphere = mesh::make_icosphere(2, 10.0);
  const auto message = [&](const std::vector<OutlineItem>& items, const GrayImage16& image,
                           const OverlayOptions& options = {}) -> std::string {
    try {
      (void)outline_overlay(view, image, items, options);
    } catch (const InvalidInputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_THAT(
      message({{"sphere", &sphere, kOutlineRed}, {"femur_r", nullptr, kOutlineRed}}, radiograph),
      AllOf(HasSubstr("item 1 ('femur_r')"), HasSubstr("null")));
  mesh::IndexedMesh broken = sphere;
  broken.V(5, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(message({{"tibia_r", &broken, kOutlineRed}}, radiograph),
              AllOf(HasSubstr("'tibia_r'"), HasSubstr("vertex 5"), HasSubstr("non-finite")));
  EXPECT_THAT(message({}, GrayImage16(10, 20)),
              AllOf(HasSubstr("view 'frontal' is 872 x 872"), HasSubstr("radiograph 10 x 20")));
  // Beyond the frontal source (y = +1300 mm): a mesh in the wrong frame or units.
  const mesh::IndexedMesh behind = mesh::make_icosphere(1, 10.0, {0, 2000, 0});
  EXPECT_THAT(message({{"pelvis", &behind, kOutlineRed}}, radiograph),
              AllOf(HasSubstr("'pelvis'"), HasSubstr("behind the source")));
  OverlayOptions options;
  options.line_width_px = 0;
  EXPECT_THAT(message({}, radiograph, options), HasSubstr("line_width_px"));
  options = {};
  options.window_low = 100;
  options.window_high = 100;
  EXPECT_THAT(message({}, radiograph, options), HasSubstr("window_low"));
  options = {};
  options.low_percentile = 99.5;
  EXPECT_THAT(message({}, radiograph, options), HasSubstr("low_percentile"));
  options = {};
  options.points = {{{0, 0, std::numeric_limits<double>::infinity()}}};
  EXPECT_THAT(message({}, radiograph, options), HasSubstr("points[0]"));
  options = {};
  options.max_width = 10;
  EXPECT_THAT(message({}, radiograph, options), HasSubstr("max_width"));
  options = {};
  options.min_contour_edges = 0;
  EXPECT_THAT(message({}, radiograph, options), HasSubstr("min_contour_edges"));
  // An empty item list is fine: the windowed radiograph alone.
  EXPECT_EQ(message({}, radiograph), "no error");
}

TEST(OutlineOverlayTest, DistinctColoursDifferPairwise) {
  const std::vector<Rgb8> colours = distinct_colours(30);
  ASSERT_EQ(colours.size(), 30U);
  for (std::size_t i = 0; i < colours.size(); ++i) {
    for (std::size_t j = i + 1; j < colours.size(); ++j) EXPECT_NE(colours[i], colours[j]);
  }
}

// Mean gradient magnitude (central differences) of the radiograph at the
// pixels drawn in full `colour`, over its mean over the whole image.
double edge_contrast(const GrayImage16& radiograph, const RgbImage8& image, Rgb8 colour) {
  double on_outline = 0;
  double everywhere = 0;
  int outline_count = 0;
  int count = 0;
  for (int y = 1; y + 1 < radiograph.height; ++y) {
    for (int x = 1; x + 1 < radiograph.width; ++x) {
      const double gx = radiograph.at(x + 1, y) - static_cast<double>(radiograph.at(x - 1, y));
      const double gy = radiograph.at(x, y + 1) - static_cast<double>(radiograph.at(x, y - 1));
      const double g = std::hypot(gx, gy);
      everywhere += g;
      ++count;
      if (get_rgb(image, x, y) == colour) {
        on_outline += g;
        ++outline_count;
      }
    }
  }
  EXPECT_GT(outline_count, 1000);  // about 15000 for the atlas's bones
  return (on_outline / std::max(1, outline_count)) / (everywhere / count);
}

// The fixture patient's own (ground-truth) bones over its radiographs: the
// outlines must sit on the bones' edges, where the radiograph changes fast,
// and no longer once the bones are moved by 3 mm.
TEST(OutlineOverlayTest, GroundTruthBonesSitOnTheirEdgesInTheFixtureRadiographs) {
  std::filesystem::path patient = test::binary_dir() / "fixtures" / "patient_1";
  if (!std::filesystem::exists(patient / "radiographs" / "views.json")) {
    patient = test::source_dir() / "build" / "fixtures" / "patient_1";
  }
  if (!std::filesystem::exists(patient / "radiographs" / "views.json")) {
    GTEST_SKIP() << "no fixture patient (tests/web builds one under <build>/fixtures)";
  }
  const RadiographPair pair = load_radiograph_pair(patient / "radiographs" / "views.json");
  const atlas::Atlas atlas = atlas::read_atlas(patient / "atlas");
  std::vector<mesh::IndexedMesh> meshes;
  std::vector<mesh::IndexedMesh> moved;
  for (const atlas::Bone& bone : atlas.bones) {
    meshes.push_back(atlas::load_mesh(patient / "atlas", bone.meshes, "lod1"));
    moved.push_back(meshes.back());
    // 3 mm toward the subject's left and front: across the long bones in both views.
    moved.back().V.rowwise() += Eigen::RowVector3d(-3, 3, 0);
  }
  std::vector<OutlineItem> items;
  std::vector<OutlineItem> moved_items;
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    items.push_back({atlas.bones[k].name, &meshes[k], kOutlineRed});
    moved_items.push_back({atlas.bones[k].name, &moved[k], kOutlineRed});
  }
  OverlayOptions options;
  options.legend = false;
  for (const RadiographFile& file : pair.views) {
    SCOPED_TRACE(file.view.name);
    const GrayImage16 radiograph = pair.image(file.view.name);
    const double aligned = edge_contrast(
        radiograph, outline_overlay(file.view, radiograph, items, options), kOutlineRed);
    const double off = edge_contrast(
        radiograph, outline_overlay(file.view, radiograph, moved_items, options), kOutlineRed);
    // Bone edges in a DRR are steep: on seed 1's outlines the gradient is
    // 11.2 (frontal) and 12.1 (lateral) times the image's mean; 3 mm (8 px)
    // off it drops to 4.6 and 5.5 (wide bones' edges still cross some of the
    // moved outlines). The bounds leave room for other seeds, the noise and
    // lod1's 4000 faces.
    EXPECT_GT(aligned, 5.0);
    EXPECT_GT(aligned, 1.5 * off);
  }
}

}  // namespace
}  // namespace mmm::image

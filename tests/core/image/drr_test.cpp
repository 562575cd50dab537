#include "core/image/drr.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/errors.h"
#include "core/mesh/primitives.h"
#include "tests/core/mesh/mesh_test_helpers.h"

namespace mmm::image {
namespace {

using ::testing::HasSubstr;

constexpr double kSphereRadius = 50.0;
constexpr int kSubdivisions = 4;  // 5120 faces, edges ~4 mm at R = 50

// A small calibrated pair: 150 x 150 mm field, 1 mm detector pitch (0.76 mm
// at the isocentre), 196 x 196 pixels.
std::array<RadiographView, 2> small_views(const Eigen::Vector3d& isocentre = {0, 0, 0}) {
  BiplanarOptions options;
  options.isocentre_mm = isocentre;
  options.detector_pixel_pitch_mm = 1.0;
  options.field_width_mm = 150;
  options.field_height_mm = 150;
  return make_biplanar_views(options);
}

mesh::IndexedMesh reversed(mesh::IndexedMesh surface) {
  surface.F.col(1).swap(surface.F.col(2));
  return surface;
}

// Two meshes' vertices and faces in one mesh (the second's indices shifted).
mesh::IndexedMesh combined(const mesh::IndexedMesh& first, const mesh::IndexedMesh& second) {
  mesh::IndexedMesh both;
  both.V.resize(first.V.rows() + second.V.rows(), 3);
  both.V << first.V, second.V;
  both.F.resize(first.F.rows() + second.F.rows(), 3);
  both.F << first.F, (second.F.array() + static_cast<int>(first.V.rows())).matrix();
  return both;
}

// The chord of an icosphere through its centre enters and leaves on faces
// whose distance from the centre is between R - gap and R (gap: the deepest
// face plane, test::icosphere_gap), so the chord is in [2 (R - gap), 2 R].
TEST(DrrTest, ChordThroughTheSphereCentreIsTwiceTheRadius) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(kSubdivisions, kSphereRadius);
  const double gap = test::icosphere_gap(sphere, kSphereRadius, Eigen::Vector3d::Zero());
  ASSERT_LT(gap, 0.1);  // ~e^2 / (6 R) for 4 mm edges: 0.05 mm
  const mesh::AabbTree tree(sphere);
  const std::vector<AttenuatingMesh> meshes = {{&tree, 1.0}};
  const auto views = small_views();
  for (const RadiographView& view : views) {
    const Ray centre = backproject(view, {0.5 * view.width, 0.5 * view.height});
    const double chord = line_integral(centre, meshes);
    EXPECT_LE(chord, 2 * kSphereRadius + 1e-9);  // 1e-9: rounding of t ~ 1300 mm
    EXPECT_GE(chord, 2 * (kSphereRadius - gap) - 1e-9);
  }
  // Off-centre: the ray toward (-0.6 R, 0, 0) passes the centre at distance
  // h (slightly less than 0.6 R: the ray is tilted). The chord 2 sqrt(R^2 -
  // h^2) changes with the radius by 2 R / sqrt(R^2 - h^2) = 2.5, so the
  // tessellation shortens it by at most 2.5 gap per end.
  const RadiographView& frontal = views[0];
  const Eigen::Vector3d target(-0.6 * kSphereRadius, 0, 0);
  const Ray ray{frontal.source_mm, (target - frontal.source_mm).normalized()};
  const double h = frontal.source_mm.cross(ray.direction).norm();
  const double expected = 2 * std::sqrt(kSphereRadius * kSphereRadius - h * h);
  EXPECT_LE(line_integral(ray, meshes), expected + 1e-9);
  EXPECT_GE(line_integral(ray, meshes), expected - 5 * gap);
  // A ray passing beside the sphere sees nothing, exactly.
  const Eigen::Vector3d above(0, 0, 1.2 * kSphereRadius);  // the ray passes ~1.2 R away
  const Ray beside{frontal.source_mm, (above - frontal.source_mm).normalized()};
  EXPECT_EQ(line_integral(beside, meshes), 0.0);
}

TEST(DrrTest, ImageOfASphereShowsItsShadowAndNothingElse) {
  const mesh::IndexedMesh sphere = mesh::make_icosphere(kSubdivisions, kSphereRadius);
  const double gap = test::icosphere_gap(sphere, kSphereRadius, Eigen::Vector3d::Zero());
  const mesh::AabbTree tree(sphere);
  const std::vector<AttenuatingMesh> meshes = {{&tree, 1.0}};
  const RadiographView view = small_views()[0];
  const FloatImage drr = render_drr(view, meshes);
  ASSERT_EQ(drr.width, view.width);
  ASSERT_EQ(drr.height, view.height);
  // The brightest pixel's ray passes within half a pixel diagonal (0.54 mm at
  // the isocentre) of the centre: its chord is 2R minus at most the
  // tessellation (2 gap) and the offset (0.54^2 / R = 0.006 mm); floats keep
  // 1e-5 mm at 100 mm.
  const float peak = *std::max_element(drr.pixels.begin(), drr.pixels.end());
  EXPECT_NEAR(peak, 2 * kSphereRadius, 2 * gap + 0.01);
  // The shadow is the disc of rays within R of the centre: a cone of half
  // angle asin(R / D) cutting the isocentre plane in radius D tan(asin(R/D)).
  const double D = (view.source_mm).norm();
  const double shadow_px = D * std::tan(std::asin(kSphereRadius / D)) / view.pixel_spacing_mm;
  int covered = 0;
  for (int y = 0; y < drr.height; ++y) {
    for (int x = 0; x < drr.width; ++x) {
      const double r = std::hypot(x + 0.5 - 0.5 * drr.width, y + 0.5 - 0.5 * drr.height);
      const float value = drr.at(x, y);
      covered += value > 0 ? 1 : 0;
      // Well outside the shadow: exactly 0 (no stray hits).
      if (r > shadow_px + 1) {
        EXPECT_EQ(value, 0.0F) << x << ", " << y;
      }
    }
  }
  // Covered pixels ~ pi r^2: the pixelated disc (an error of ~ its perimeter
  // times a fraction of a pixel, 0.5 % at r = 65 px) shrunk by the inscribed
  // polyhedron (2 gap / R = 0.2 %): 2 % is a comfortable bound.
  EXPECT_NEAR(covered / (std::numbers::pi * shadow_px * shadow_px), 1.0, 0.02);
}

TEST(DrrTest, NestedMeshesAdd) {
  const double inner_radius = 25.0;
  const mesh::IndexedMesh outer = mesh::make_icosphere(kSubdivisions, kSphereRadius);
  const mesh::IndexedMesh inner = mesh::make_icosphere(kSubdivisions, inner_radius);
  const double gap_outer = test::icosphere_gap(outer, kSphereRadius, Eigen::Vector3d::Zero());
  const double gap_inner = test::icosphere_gap(inner, inner_radius, Eigen::Vector3d::Zero());
  const mesh::AabbTree outer_tree(outer);
  const mesh::AabbTree inner_tree(inner);
  const std::vector<AttenuatingMesh> meshes = {{&outer_tree, kSoftTissueMuPerMm},
                                               {&inner_tree, kBoneMuPerMm}};
  const RadiographView view = small_views()[1];
  const Ray centre = backproject(view, {0.5 * view.width, 0.5 * view.height});
  const double expected = kSoftTissueMuPerMm * 2 * kSphereRadius + kBoneMuPerMm * 2 * inner_radius;
  // Each chord is short by at most twice its sphere's gap (see above).
  const double tolerance = 2 * (kSoftTissueMuPerMm * gap_outer + kBoneMuPerMm * gap_inner) + 1e-9;
  EXPECT_NEAR(line_integral(centre, meshes), expected, tolerance);
  // Zero mu contributes nothing; order does not matter.
  const std::vector<AttenuatingMesh> swapped = {
      {&inner_tree, kBoneMuPerMm}, {&outer_tree, kSoftTissueMuPerMm}, {&inner_tree, 0.0}};
  EXPECT_NEAR(line_integral(centre, swapped), line_integral(centre, meshes), 1e-12);
}

// One mesh made of an outer sphere and an inward-facing inner sphere: a
// hollow ball (a bone with its marrow canal). Through the centre the ray is
// inside for 2 (R - r), not 2 R.
TEST(DrrTest, InwardFacingShellIsACavity) {
  const double inner_radius = 20.0;
  const mesh::IndexedMesh outer = mesh::make_icosphere(kSubdivisions, kSphereRadius);
  const mesh::IndexedMesh inner = mesh::make_icosphere(kSubdivisions, inner_radius);
  const double gap_outer = test::icosphere_gap(outer, kSphereRadius, Eigen::Vector3d::Zero());
  const double gap_inner = test::icosphere_gap(inner, inner_radius, Eigen::Vector3d::Zero());
  const mesh::AabbTree hollow(combined(outer, reversed(inner)));
  const std::vector<AttenuatingMesh> meshes = {{&hollow, 1.0}};
  const RadiographView view = small_views()[0];
  const Ray centre = backproject(view, {0.5 * view.width, 0.5 * view.height});
  // The outer chord is short by up to 2 gap_outer, the cavity's by up to
  // 2 gap_inner (which lengthens the wall).
  EXPECT_NEAR(line_integral(centre, meshes), 2 * (kSphereRadius - inner_radius),
              2 * (gap_outer + gap_inner));
  // render_drr accepts it: the enclosed volume is positive.
  EXPECT_NO_THROW((void)render_drr(view, meshes));
}

// Two overlapping spheres in one mesh count once where they overlap (the
// depth count is a winding number), not twice.
TEST(DrrTest, OverlappingComponentsOfOneMeshCountOnce) {
  const mesh::IndexedMesh a = mesh::make_icosphere(kSubdivisions, kSphereRadius, {0, 0, 0});
  const mesh::IndexedMesh b = mesh::make_icosphere(kSubdivisions, kSphereRadius, {0, -30, 0});
  const mesh::AabbTree both(combined(a, b));
  const std::vector<AttenuatingMesh> meshes = {{&both, 1.0}};
  // The frontal central ray runs along -y through both centres: the union
  // spans y in [-30 - R, R], 2 R + 30 mm.
  const RadiographView view = small_views()[0];
  const Ray centre = backproject(view, {0.5 * view.width, 0.5 * view.height});
  const double gap = test::icosphere_gap(a, kSphereRadius, Eigen::Vector3d::Zero());
  EXPECT_NEAR(line_integral(centre, meshes), 2 * kSphereRadius + 30, 2 * gap);
}

TEST(DrrTest, ThreadCountDoesNotChangeTheImage) {
  const mesh::AabbTree tree(mesh::make_icosphere(3, 40.0, {10, -5, 20}));
  const std::vector<AttenuatingMesh> meshes = {{&tree, kBoneMuPerMm}};
  const RadiographView view = small_views()[0];
  DrrOptions one;
  one.threads = 1;
  DrrOptions three;
  three.threads = 3;
  // Every pixel is computed by the same code whichever thread runs it.
  EXPECT_EQ(render_drr(view, meshes, one).pixels, render_drr(view, meshes, three).pixels);
}

TEST(DrrTest, RadiographIsDeterministicForASeedAndShowsBoneBright) {
  const mesh::AabbTree tree(mesh::make_icosphere(3, 40.0));
  const std::vector<AttenuatingMesh> meshes = {{&tree, kBoneMuPerMm}};
  const FloatImage drr = render_drr(small_views()[0], meshes);
  RadiographOptions options;
  options.seed = 42;
  const GrayImage16 first = to_radiograph(drr, options);
  const GrayImage16 again = to_radiograph(drr, options);
  EXPECT_EQ(first.pixels, again.pixels);
  options.seed = 43;
  EXPECT_NE(to_radiograph(drr, options).pixels, first.pixels);
  const int cx = drr.width / 2;
  const int cy = drr.height / 2;
  // Through the ball (L = 0.05 * 80 = 4): offset + 6000 * 4 = 25000 counts,
  // noise ~ 6000 / sqrt(1e5 e^-4) = 140 counts; air: the offset, noise ~19.
  EXPECT_NEAR(first.at(cx, cy), 25000, 5 * 140);
  EXPECT_NEAR(first.at(2, 2), 1000, 5 * 19);

  RadiographOptions clean;
  clean.quantum_noise = false;
  const GrayImage16 noiseless = to_radiograph(drr, clean);
  for (std::size_t i = 0; i < drr.pixels.size(); ++i) {
    ASSERT_EQ(noiseless.pixels[i],
              static_cast<std::uint16_t>(std::lround(1000.0 + 6000.0 * drr.pixels[i])));
  }
}

// For a constant line integral L the measured attenuation has standard
// deviation 1 / sqrt(N), N = N0 exp(-L) (delta method on -ln N'), so the
// pixels spread by gain / sqrt(N).
TEST(DrrTest, QuantumNoiseHasTheModelledSpread) {
  FloatImage flat(400, 250, 2.0F);
  RadiographOptions options;
  options.photons_per_pixel = 1e4;
  options.readout_noise_counts = 50;
  const GrayImage16 image = to_radiograph(flat, options);
  double sum = 0;
  double sum_squared = 0;
  for (const std::uint16_t value : image.pixels) {
    sum += value;
    sum_squared += static_cast<double>(value) * value;
  }
  const auto n = static_cast<double>(image.pixels.size());
  const double mean = sum / n;
  const double sd = std::sqrt(sum_squared / n - mean * mean);
  const double quantum = 6000.0 / std::sqrt(1e4 * std::exp(-2.0));
  const double expected_sd = std::hypot(quantum, 50.0);
  // 1e5 samples estimate a standard deviation to 0.2 % (1 / sqrt(2 n)); the
  // delta method's error at N = 1353 photons is ~1 / N; 3 % covers both with
  // a wide margin.
  EXPECT_NEAR(sd / expected_sd, 1.0, 0.03);
  // Mean: offset + gain * L, biased by ~gain / (2 N) = 2 counts.
  EXPECT_NEAR(mean, 1000 + 6000 * 2.0, 5);
}

TEST(DrrTest, BadInputIsRejected) {
  const mesh::AabbTree tree(mesh::make_icosphere(2, 30.0));
  const mesh::AabbTree inside_out(reversed(mesh::make_icosphere(2, 30.0)));
  const RadiographView view = small_views()[0];
  const std::vector<AttenuatingMesh> null_tree = {{nullptr, 1.0}};
  EXPECT_THAT([&] { (void)render_drr(view, null_tree); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("mesh 0 has no tree")));
  const std::vector<AttenuatingMesh> nan_mu = {{&tree, 1.0}, {&tree, std::nan("")}};
  EXPECT_THAT([&] { (void)render_drr(view, nan_mu); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("mesh 1")));
  const std::vector<AttenuatingMesh> flipped = {{&inside_out, 1.0}};
  EXPECT_THAT([&] { (void)render_drr(view, flipped); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("inside out")));
  const std::vector<AttenuatingMesh> good = {{&tree, 1.0}};
  DrrOptions no_threads;
  no_threads.threads = 0;
  EXPECT_THROW((void)render_drr(view, good, no_threads), InvalidInputError);
  RadiographView broken = view;
  broken.pixel_spacing_mm = 0;
  EXPECT_THROW((void)render_drr(broken, good), InvalidInputError);
  EXPECT_THROW((void)line_integral({view.source_mm, Eigen::Vector3d::Zero()}, good),
               InvalidInputError);

  FloatImage with_nan(2, 2, 1.0F);
  with_nan.at(1, 1) = std::nanf("");
  EXPECT_THAT([&] { (void)to_radiograph(with_nan); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("pixel (1, 1)")));
  RadiographOptions photons;
  photons.photons_per_pixel = 0.5;
  EXPECT_THROW((void)to_radiograph(FloatImage(2, 2), photons), InvalidInputError);
  RadiographOptions gain;
  gain.counts_per_attenuation = -1;
  EXPECT_THAT([&] { (void)to_radiograph(FloatImage(2, 2), gain); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("counts_per_attenuation")));
}

}  // namespace
}  // namespace mmm::image

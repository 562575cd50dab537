// Calibration of a view from beads of known position: exact on noiseless
// pixels for both models, per-bead residuals at the noise level, the bead
// detector's refinement, and the errors of a calibration that cannot work.
#include "core/image/bead_calibration.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/errors.h"
#include "core/image/drr.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/primitives.h"

namespace mmm::image {
namespace {

using ::testing::HasSubstr;

// A calibration cage: beads on three rings at several heights and radii.
std::vector<Eigen::Vector3d> cage(const Eigen::Vector3d& centre) {
  std::vector<Eigen::Vector3d> beads;
  for (int level = 0; level < 5; ++level) {
    for (int k = 0; k < 6; ++k) {
      const double angle = (k + 0.5 * level) * 2 * M_PI / 6;
      const double radius = 80.0 + 30.0 * (level % 2);
      beads.emplace_back(centre + Eigen::Vector3d(radius * std::cos(angle),
                                                  radius * std::sin(angle), -700 + 350 * level));
    }
  }
  return beads;
}

std::array<RadiographView, 2> system_views(ProjectionModel model) {
  BiplanarOptions options;
  options.model = model;
  options.isocentre_mm = {5, -10, 900};
  options.field_height_mm = 1700;
  options.detector_pixel_pitch_mm = 0.5;
  return make_biplanar_views(options);
}

std::vector<BeadPixel> observe(const RadiographView& view, const std::vector<Eigen::Vector3d>& at,
                               double noise_px, unsigned seed) {
  std::mt19937 rng(seed);
  // A normal distribution needs a spread > 0 (checked under _GLIBCXX_ASSERTIONS).
  std::normal_distribution<double> noise(0.0, noise_px > 0 ? noise_px : 1.0);
  const double gain = noise_px > 0 ? 1.0 : 0.0;
  std::vector<BeadPixel> beads;
  for (std::size_t i = 0; i < at.size(); ++i) {
    const Eigen::Vector2d offset(noise(rng), noise(rng));
    beads.push_back({"b" + std::to_string(i), at[i], project(view, at[i]) + gain * offset});
  }
  return beads;
}

TEST(BeadCalibrationTest, NoiselessBeadsGiveTheViewBackForBothModels) {
  for (const auto model : {ProjectionModel::kPinhole, ProjectionModel::kSlotScanning}) {
    for (const RadiographView& truth : system_views(model)) {
      const auto beads = cage({5, -10, 900});
      const BeadCalibration calibration = calibrate_view_from_beads(
          truth.name, truth.width, truth.height, model, observe(truth, beads, 0.0, 1));
      EXPECT_EQ(calibration.view.model, model);
      EXPECT_LT(calibration.max_mm, 1e-6) << truth.name;
      EXPECT_EQ(calibration.residuals.size(), beads.size());
      // Anywhere in the field, not only at the beads.
      std::mt19937 rng(4);
      std::uniform_real_distribution<double> unit(-1.0, 1.0);
      for (int i = 0; i < 30; ++i) {
        const Eigen::Vector3d X =
            Eigen::Vector3d(5, -10, 900) +
            Eigen::Vector3d(150 * unit(rng), 150 * unit(rng), 750 * unit(rng));
        EXPECT_LT((project(calibration.view, X) - project(truth, X)).norm(), 1e-5);
      }
      EXPECT_LT((source_for(calibration.view, beads[0]) - source_for(truth, beads[0])).norm(),
                1e-4);
      EXPECT_NEAR(calibration.view.pixel_spacing_mm, truth.pixel_spacing_mm,
                  1e-3 * truth.pixel_spacing_mm);
    }
  }
}

TEST(BeadCalibrationTest, ResidualsReportTheClickNoise) {
  const RadiographView truth = system_views(ProjectionModel::kSlotScanning)[0];
  const auto beads = cage({5, -10, 900});
  const BeadCalibration calibration =
      calibrate_view_from_beads(truth.name, truth.width, truth.height,
                                ProjectionModel::kSlotScanning, observe(truth, beads, 0.5, 2));
  EXPECT_TRUE(calibration.converged);
  // Half-pixel clicks: residuals of that order (fewer degrees of freedom
  // than beads keep them a little below it), the view within a pixel.
  const double spacing = truth.pixel_spacing_mm;
  EXPECT_GT(calibration.rms_mm, 0.3 * spacing);
  EXPECT_LT(calibration.rms_mm, 1.0 * spacing);
  const Eigen::Vector3d middle(5, -10, 900);
  EXPECT_LT((project(calibration.view, middle) - project(truth, middle)).norm(), 1.0);
}

TEST(BeadCalibrationTest, TooFewOrFlatBeadsAreRefused) {
  const RadiographView truth = system_views(ProjectionModel::kPinhole)[0];
  auto beads = observe(truth, cage({5, -10, 900}), 0.0, 1);
  const std::vector<BeadPixel> five(beads.begin(), beads.begin() + 5);
  EXPECT_THAT(
      [&] {
        calibrate_view_from_beads("frontal", truth.width, truth.height, ProjectionModel::kPinhole,
                                  five);
      },
      ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("at least 6")));
  beads[3].bead = beads[2].bead;
  EXPECT_THAT(
      [&] {
        calibrate_view_from_beads("frontal", truth.width, truth.height, ProjectionModel::kPinhole,
                                  beads);
      },
      ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("given twice")));
  std::vector<BeadPixel> flat;
  for (int i = 0; i < 12; ++i) {
    const int column = i % 4;
    const int row = i / 4;
    const Eigen::Vector3d X(5.0 + 20.0 * column, -10.0, 700.0 + 100.0 * row);
    flat.push_back({"f" + std::to_string(i), X, project(truth, X)});
  }
  EXPECT_THROW(calibrate_view_from_beads("frontal", truth.width, truth.height,
                                         ProjectionModel::kSlotScanning, flat),
               InvalidInputError);
}

TEST(BeadCalibrationTest, TheDetectorFindsABeadsCentreFromAnOffClick) {
  // A bead of 3 mm diameter rendered into a small pinhole view.
  BiplanarOptions options;
  options.field_width_mm = 60;
  options.field_height_mm = 60;
  options.detector_pixel_pitch_mm = 0.3;
  const RadiographView view = make_biplanar_views(options)[0];
  mesh::IndexedMesh bead = mesh::make_icosphere(4, 1.5);
  const Eigen::Vector3d at(4.3, 2.0, -6.1);
  bead.V.rowwise() += at.transpose();
  const mesh::AabbTree tree(bead);
  const std::vector<AttenuatingMesh> materials = {{&tree, 1.0}};
  const FloatImage integrals = render_drr(view, materials, DrrOptions{1});
  GrayImage16 image(integrals.width, integrals.height);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    image.pixels[i] = static_cast<std::uint16_t>(1000 + 5000 * integrals.pixels[i]);
  }
  const Eigen::Vector2d truth = project(view, at);
  const Eigen::Vector2d refined = refine_bead_pixel(image, truth + Eigen::Vector2d(3, -2), 10.0);
  EXPECT_LT((refined - truth).norm(), 0.25);
  EXPECT_THROW(refine_bead_pixel(image, {-5, 3}, 10.0), InvalidInputError);
}

}  // namespace
}  // namespace mmm::image

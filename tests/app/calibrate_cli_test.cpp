// mmm calibrate: a pair calibrated from a calibration object's beads, the
// sidecar reproducing the system, each bead's residual reported, and bad
// files refused naming the field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <random>

#include "core/image/png.h"
#include "core/image/projection.h"
#include "tests/support/test_data.h"

namespace mmm {
namespace {

using test::run_mmm;
using ::testing::HasSubstr;
using Json = nlohmann::json;

class CalibrateCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    image::BiplanarOptions options;
    options.model = image::ProjectionModel::kSlotScanning;
    options.isocentre_mm = {0, 0, 800};
    options.field_height_mm = 1200;
    options.detector_pixel_pitch_mm = 2.0;  // small images
    views_ = image::make_biplanar_views(options);
    Json beads = Json::object();
    for (int level = 0; level < 4; ++level) {
      for (int k = 0; k < 5; ++k) {
        const double angle = (k + 0.5 * level) * 2 * M_PI / 5;
        const double radius = 70.0 + 40.0 * (level % 2);
        const Eigen::Vector3d X(radius * std::cos(angle), radius * std::sin(angle),
                                350 + 300 * level);
        const int number = 5 * level + k;
        const std::string name = (number < 10 ? "b0" : "b") + std::to_string(number);
        beads[name] = {X.x(), X.y(), X.z()};
        beads_[name] = X;
      }
    }
    test::write_file(root_ / "cage.json", Json{{"format", "mmm-calibration-object"},
                                               {"version", 1},
                                               {"name", "cage"},
                                               {"beads", beads}}
                                              .dump());
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.3);
    Json views = Json::object();
    for (const image::RadiographView& view : views_) {
      image::write_png(image::GrayImage16(view.width, view.height, 1000),
                       root_ / (view.name + ".png"));
      for (const auto& [name, X] : beads_) {
        const Eigen::Vector2d pixel = image::project(view, X);
        views[view.name][name] = {pixel.x() + noise(rng), pixel.y() + noise(rng)};
      }
    }
    test::write_file(root_ / "clicks.json",
                     Json{{"format", "mmm-bead-clicks"}, {"version", 1}, {"views", views}}.dump());
  }

  std::string command(const std::string& clicks = "clicks.json") const {
    return "calibrate --object " + (root_ / "cage.json").string() + " --clicks " +
           (root_ / clicks).string() + " --frontal " + (root_ / "frontal.png").string() +
           " --lateral " + (root_ / "lateral.png").string() + " -o " + (root_ / "out").string();
  }

  test::ScratchDir root_{"calibrate-cli"};
  std::array<image::RadiographView, 2> views_;
  std::map<std::string, Eigen::Vector3d> beads_;
};

TEST_F(CalibrateCliTest, WritesASidecarThatReproducesTheSystem) {
  const auto result = run_mmm(command());
  ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
  EXPECT_THAT(result.out, HasSubstr("residual RMS"));
  EXPECT_THAT(result.out, HasSubstr("b19"));
  const std::vector<image::RadiographFile> files =
      image::read_view_sidecar(root_ / "out" / "views.json");
  ASSERT_EQ(files.size(), 2U);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(files[k].view.model, image::ProjectionModel::kSlotScanning);
    EXPECT_EQ(files[k].image, views_[k].name + ".png");
    // 0.3-pixel clicks on 20 beads: the view within half a pixel at the
    // centre of the cage.
    const Eigen::Vector3d centre(0, 0, 800);
    EXPECT_LT((image::project(files[k].view, centre) - image::project(views_[k], centre)).norm(),
              0.5);
  }
  const Json report = Json::parse(test::read_text(root_ / "out" / "calibration_report.json"));
  EXPECT_EQ(report["views"]["frontal"]["beads"].size(), 20U);
  EXPECT_LT(report["views"]["lateral"]["rms_mm"].get<double>(), 0.5 * views_[1].pixel_spacing_mm);
}

TEST_F(CalibrateCliTest, AClickOnAnUnknownBeadIsRefusedNamingIt) {
  Json clicks = Json::parse(test::read_text(root_ / "clicks.json"));
  clicks["views"]["frontal"]["b99"] = {10, 10};
  test::write_file(root_ / "bad.json", clicks.dump());
  const auto result = run_mmm(command("bad.json"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_THAT(result.err, HasSubstr("views.frontal.b99: unknown bead"));
}

}  // namespace
}  // namespace mmm

// The landmark nodes around the station: load_radiographs (a checked
// RadiographPair from a calibration and two images), landmark_report,
// import_markups (3D Slicer) and static_trial_landmarks (real gait2392
// static trial).

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/hash/sha256.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "core/landmarks/landmark_set.h"
#include "nodes/import_markups.h"
#include "nodes/landmark_report.h"
#include "nodes/load_radiographs.h"
#include "nodes/static_trial_landmarks.h"
#include "tests/nodes/node_harness.h"

namespace mmm::nodes {
namespace {

using Json = nlohmann::json;
using workflow::PortType;

landmarks::LandmarkSet read_set(const workflow::ArtifactRef& ref) {
  return landmarks::landmark_set_from_json_text(mmm::test::read_text(ref.path), "output");
}

TEST(LoadRadiographsTest, PairsTheImagesWithTheirViewsAndRejectsAWrongSize) {
  test::NodeHarness harness;
  image::BiplanarOptions options;
  options.field_width_mm = 60;
  options.field_height_mm = 90;
  options.detector_pixel_pitch_mm = 2;
  std::vector<image::RadiographFile> files;
  for (const image::RadiographView& view : image::make_biplanar_views(options)) {
    image::write_png(image::GrayImage16(view.width, view.height),
                     harness.folder() / (view.name + ".png"));
    files.push_back({view, view.name + ".png"});
  }
  image::write_view_sidecar(harness.folder() / "views.json", files);
  const auto calibration = harness.add_file(PortType::kFile, harness.folder() / "views.json");
  const auto frontal = harness.add_file(PortType::kFile, harness.folder() / "frontal.png");
  const auto lateral = harness.add_file(PortType::kFile, harness.folder() / "lateral.png");
  const auto outputs = harness.run<LoadRadiographs>(
      {{"calibration", calibration}, {"frontal", frontal}, {"lateral", lateral}});
  const image::RadiographPair pair = image::radiograph_pair_from_json_text(
      mmm::test::read_text(outputs.at("radiographs").path), "output");
  EXPECT_EQ(pair.views.size(), 2U);
  EXPECT_EQ(pair.image_sha256("lateral"),
            hash::sha256_hex(mmm::test::read_text(harness.folder() / "lateral.png")));

  image::write_png(image::GrayImage16(5, 5), harness.folder() / "small.png");
  const auto small = harness.add_file(PortType::kFile, harness.folder() / "small.png");
  EXPECT_THROW(harness.run<LoadRadiographs>(
                   {{"calibration", calibration}, {"frontal", frontal}, {"lateral", small}}),
               IoError);
}

TEST(LandmarkReportTest, ReportsDistancesAlongTheLegAndReprojectionErrors) {
  test::NodeHarness harness;
  landmarks::LandmarkSet set;
  set.source = "radiographs";
  set.landmarks.push_back({"femoral_head_centre_r", {0, 0, 900}, {{"frontal", 0.5}}, {}});
  set.landmarks.push_back({"patella_centre_r", {0, 30, 500}, {{"frontal", 1.5}}, {}});
  set.landmarks.push_back({"ankle_centre_r", {0, 0, 100}, {}, {}});
  const auto outputs = harness.run<LandmarkReport>(
      {{"landmarks",
        harness.add(PortType::kLandmarkSet, landmarks::landmark_set_to_json_text(set))}});
  const Json report = Json::parse(mmm::test::read_text(outputs.at("report").path));
  EXPECT_NEAR(report["distances_mm"]["femoral_head_centre_r-patella_centre_r"].get<double>(),
              std::hypot(30.0, 400.0), 1e-9);
  EXPECT_NEAR(report["distances_mm"]["patella_centre_r-ankle_centre_r"].get<double>(),
              std::hypot(30.0, 400.0), 1e-9);
  EXPECT_DOUBLE_EQ(report["reprojection_error_mm"]["max"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(report["reprojection_error_mm"]["mean"].get<double>(), 1.0);
}

TEST(ImportMarkupsTest, ReadsAnLpsPointListIntoThePatientFrame) {
  test::NodeHarness harness;
  const std::string file = R"json({"markups": [{"type": "Fiducial", "coordinateSystem": "LPS",
    "coordinateUnits": "mm", "controlPoints": [
      {"label": "femoral head", "position": [-90.0, -5.0, 900.0], "positionStatus": "defined"},
      {"label": "patella_centre_r", "position": [-80.0, -30.0, 480.0], "positionStatus": "defined"}]}]})json";
  const auto outputs =
      harness.run<ImportMarkups>({{"markups", harness.add(PortType::kFile, file)}});
  const landmarks::LandmarkSet set = read_set(outputs.at("landmarks"));
  ASSERT_NE(set.find("femoral_head_centre_r"), nullptr);
  EXPECT_TRUE(
      set.find("femoral_head_centre_r")
          ->position_mm.isApprox(Eigen::Vector3d(90, 5, 900)));  // LPS -> RAS: x and y change sign
  EXPECT_EQ(set.source, "slicer_markups");
}

TEST(StaticTrialLandmarksTest, RealStaticTrialGivesAPlausibleFemurLength) {
  test::NodeHarness harness;
  const auto trial = harness.add_file(
      PortType::kFile, mmm::test::data_dir() / "gait2392/Pipelines/subject01_static.trc");
  const auto outputs = harness.run<StaticTrialLandmarks>({{"trial", trial}}, {{"legs", "right"}});
  const landmarks::LandmarkSet set = read_set(outputs.at("landmarks"));
  ASSERT_NE(set.find("femoral_head_centre_r"), nullptr);
  ASSERT_NE(set.find("knee_centre_r"), nullptr);
  EXPECT_EQ(set.find("femoral_head_centre_l"), nullptr);
  const double femur =
      (set.find("femoral_head_centre_r")->position_mm - set.find("knee_centre_r")->position_mm)
          .norm();
  // The OpenSim-scaled model of this subject has a 454 mm femur.
  EXPECT_NEAR(femur, 454.1, 15.0);
  EXPECT_EQ(set.frame, "lab");
}

}  // namespace
}  // namespace mmm::nodes

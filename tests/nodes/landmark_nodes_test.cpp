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

// A Slicer point list of the default atlas's bony landmarks (RAS, mm) with
// the labels people use, declared as `system`; `negate` flips x and y.
std::string atlas_point_list(const std::string& system, bool negate) {
  const std::vector<std::pair<std::string, Eigen::Vector3d>> points = {
      {"Femoral Head Center R", {637.1, 448.8, 882.9}},
      {"Patella", {637.9, 475.9, 513.0}},
      {"Ankle Centre", {583.3, 407.5, 143.8}},
      {"RASIS", {677.4, 491.3, 975.8}},
      {"LASIS", {400.1, 497.5, 978.7}},
      {"V Sacral", {535.7, 350.6, 961.5}},
      {"R Knee Lat", {656.1, 419.6, 504.3}},
      {"RME", {578.2, 433.1, 505.2}},
      {"Lateral Malleolus R", {616.9, 395.9, 155.2}},
      {"R Ankle Med", {571.3, 413.4, 171.8}},
      {"Heel", {575.7, 355.3, 142.1}}};
  Json list = Json::array();
  for (const auto& [label, p] : points) {
    const double s = negate ? -1.0 : 1.0;
    list.push_back({{"label", label}, {"position", {s * p.x(), s * p.y(), p.z()}}});
  }
  return Json{{"markups", Json::array({{{"type", "Fiducial"},
                                        {"coordinateSystem", system},
                                        {"controlPoints", list}}})}}
      .dump();
}

std::string import_error(const std::string& file) {
  test::NodeHarness harness;
  try {
    harness.run<ImportMarkups>({{"markups", harness.add(PortType::kFile, file)}});
  } catch (const std::exception& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(ImportMarkupsTest, ARightFilePassesAndAMirroredOneIsRejectedWithTheHint) {
  test::NodeHarness harness;
  const auto outputs = harness.run<ImportMarkups>(
      {{"markups", harness.add(PortType::kFile, atlas_point_list("RAS", false))}});
  const landmarks::LandmarkSet set = read_set(outputs.at("landmarks"));
  EXPECT_EQ(set.landmarks.size(), 11U);
  ASSERT_NE(set.find("medial_epicondyle_r"), nullptr);
  EXPECT_EQ(set.find("heel_r")->position_mm, Eigen::Vector3d(575.7, 355.3, 142.1));
  // The same points with x and y negated, still declared RAS: LPS really.
  const std::string mirrored = import_error(atlas_point_list("RAS", true));
  EXPECT_NE(mirrored.find("fail the anatomical checks"), std::string::npos) << mirrored;
  EXPECT_NE(mirrored.find("the points look like LPS coordinates read as RAS"), std::string::npos)
      << mirrored;
  EXPECT_NE(mirrored.find("coordinateSystem to \"LPS\""), std::string::npos) << mirrored;
  // Declared LPS, they are read right.
  test::NodeHarness lps;
  EXPECT_NO_THROW(lps.run<ImportMarkups>(
      {{"markups", lps.add(PortType::kFile, atlas_point_list("LPS", true))}}));
}

TEST(ImportMarkupsTest, AnUnknownLabelIsRejectedListingTheKnownOnes) {
  const std::string message = import_error(R"json({"markups": [{"type": "Fiducial",
    "coordinateSystem": "RAS", "controlPoints": [
      {"label": "RASIS", "position": [677.4, 491.3, 975.8]},
      {"label": "greater trochanter", "position": [670.0, 440.0, 860.0]}]}]})json");
  EXPECT_NE(message.find("'greater trochanter' names no landmark"), std::string::npos) << message;
  EXPECT_NE(message.find("lateral_epicondyle_r (R Lateral Epicondyle"), std::string::npos)
      << message;
  EXPECT_NE(message.find("Heel: the most posterior point of the calcaneal tuberosity"),
            std::string::npos);
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

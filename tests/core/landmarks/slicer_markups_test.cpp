#include "core/landmarks/slicer_markups.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::landmarks {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A point list as Slicer 5 saves it (trimmed of display settings), LPS.
constexpr const char* kSlicerFile = R"({
  "@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/markups-schema-v1.0.3.json#",
  "markups": [
    {
      "type": "Fiducial",
      "coordinateSystem": "LPS",
      "coordinateUnits": "mm",
      "locked": false,
      "fixedNumberOfControlPoints": false,
      "labelFormat": "%N-%d",
      "lastUsedControlPointNumber": 4,
      "controlPoints": [
        {"id": "1", "label": "femoral_head_centre_r", "description": "", "associatedNodeID": "",
         "position": [-90.5, 10.25, 900.0],
         "orientation": [-1.0, -0.0, -0.0, -0.0, -1.0, -0.0, 0.0, 0.0, 1.0],
         "selected": true, "locked": false, "visibility": true, "positionStatus": "defined"},
        {"id": "2", "label": "Patella Center R", "position": [-80.0, -30.0, 480.0],
         "positionStatus": "defined"},
        {"id": "3", "label": "ankle", "position": [0.0, 0.0, 0.0],
         "positionStatus": "undefined"},
        {"id": "4", "label": "R Knee Lat", "position": [-70.0, -5.0, 500.0],
         "positionStatus": "defined"}
      ],
      "measurements": [],
      "display": {"visibility": true, "opacity": 1.0}
    },
    {"type": "Line", "coordinateSystem": "LPS", "controlPoints": []}
  ]
})";

// The message of the IoError `read` throws; "" when it throws nothing.
template <typename F>
std::string io_error_of(F&& read) {
  try {
    read();
  } catch (const IoError& error) {
    return error.what();
  }
  return {};
}

TEST(SlicerMarkupsTest, ReadsAPointListInLpsAsRas) {
  const test::ScratchDir dir("markups");
  const auto file = test::write_file(dir / "landmarks.mrk.json", kSlicerFile);
  const MarkupsReadResult result = read_slicer_markups(file);
  const LandmarkSet& set = result.landmarks;
  EXPECT_EQ(set.frame, "patient");
  EXPECT_EQ(set.source, "slicer_markups");
  ASSERT_THAT(set.names(),
              ElementsAre("femoral_head_centre_r", "patella_centre_r", "lateral_epicondyle_r"));
  EXPECT_EQ(result.coordinate_system, "LPS");
  // LPS -> RAS: x and y change sign, z stays.
  EXPECT_EQ(set.landmarks[0].position_mm, Eigen::Vector3d(90.5, -10.25, 900.0));
  EXPECT_EQ(set.landmarks[1].position_mm, Eigen::Vector3d(80.0, 30.0, 480.0));
  // Notes: the renamed labels, the undefined point, the line.
  ASSERT_EQ(result.notes.size(), 4U);
  EXPECT_THAT(result.notes[0], HasSubstr("label 'Patella Center R' read as 'patella_centre_r'"));
  EXPECT_THAT(result.notes[1],
              AllOf(HasSubstr("markups[0].controlPoints[2] ('ankle')"), HasSubstr("undefined")));
  EXPECT_THAT(result.notes[2], HasSubstr("label 'R Knee Lat' read as 'lateral_epicondyle_r'"));
  EXPECT_THAT(result.notes[3], HasSubstr("markups[1]: markup of type 'Line' ignored"));
}

TEST(SlicerMarkupsTest, AnUnknownLabelIsAnErrorListingTheKnownLabels) {
  const test::ScratchDir dir("markups");
  const auto file = test::write_file(dir / "unknown.mrk.json", R"({"markups": [{
      "type": "Fiducial", "coordinateSystem": "RAS", "controlPoints": [
        {"label": "RASIS", "position": [677, 491, 976]},
        {"label": "lesser trochanter", "position": [620, 440, 820]}]}]})");
  const std::string message = io_error_of([&] { read_slicer_markups(file); });
  EXPECT_THAT(message,
              AllOf(HasSubstr("unknown.mrk.json"), HasSubstr("markups[0].controlPoints[1].label"),
                    HasSubstr("'lesser trochanter' names no landmark"),
                    // The table: atlas names, labels and definitions.
                    HasSubstr("asis_r (R ASIS"), HasSubstr("heel_r ("),
                    HasSubstr("Lateral femoral epicondyle: the most prominent point")));
}

TEST(SlicerMarkupsTest, HonoursRasAndUnits) {
  const test::ScratchDir dir("markups");
  const auto file = test::write_file(dir / "ras.mrk.json", R"({"markups": [{
      "type": "Fiducial", "coordinateSystem": "RAS", "coordinateUnits": "m",
      "controlPoints": [{"label": "hip centre", "position": [0.09, 0.01, 0.9]}]}]})");
  const MarkupsReadResult result = read_slicer_markups(file);
  ASSERT_EQ(result.landmarks.landmarks.size(), 1U);
  EXPECT_EQ(result.landmarks.landmarks[0].name, "femoral_head_centre_r");
  // m -> mm: one rounding of each product.
  EXPECT_TRUE(
      result.landmarks.landmarks[0].position_mm.isApprox(Eigen::Vector3d(90, 10, 900), 1e-15));
  // No coordinateSystem: Slicer's default, LPS.
  const auto lps = test::write_file(dir / "default.mrk.json", R"({"markups": [{
      "type": "Fiducial", "controlPoints": [{"label": "KJC", "position": [1, 2, 3]}]}]})");
  const LandmarkSet set = read_slicer_markups(lps).landmarks;
  EXPECT_EQ(set.landmarks[0].name, "knee_centre_r");
  EXPECT_EQ(set.landmarks[0].position_mm, Eigen::Vector3d(-1, -2, 3));
}

TEST(SlicerMarkupsTest, LabelsMatchExactlyThenLooselyThenByAlias) {
  EXPECT_EQ(match_landmark_name("patella_centre_r"), "patella_centre_r");
  EXPECT_EQ(match_landmark_name("PATELLA CENTRE R"), "patella_centre_r");
  EXPECT_EQ(match_landmark_name("Femoral-Head-Center_R"), "femoral_head_centre_r");
  EXPECT_EQ(match_landmark_name("femoral head"), "femoral_head_centre_r");
  EXPECT_EQ(match_landmark_name("Femoral head right"), "femoral_head_centre_r");
  EXPECT_EQ(match_landmark_name("Ankle Center"), "ankle_centre_r");
  EXPECT_EQ(match_landmark_name("RASIS"), "asis_r");
  EXPECT_EQ(match_landmark_name("V Sacral"), "sacral_point");
  EXPECT_EQ(match_landmark_name("F-1"), "");
  EXPECT_EQ(match_landmark_name("  "), "");
  MarkupsReadOptions options;
  options.aliases["fh"] = "femoral_head_centre_r";
  EXPECT_EQ(match_landmark_name("FH", options), "femoral_head_centre_r");
}

TEST(SlicerMarkupsTest, RoundTripThroughTheWriter) {
  LandmarkSet set;
  set.source = "radiographs";
  set.landmarks = {{"femoral_head_centre_r", {90.125, -3.5, 900.0 / 7.0}, {}, {}},
                   {"patella_centre_r", {80, 30, 480}, {}, {}}};
  const test::ScratchDir dir("markups");
  for (const char* system : {"LPS", "RAS"}) {
    SCOPED_TRACE(system);
    const auto file = dir / (std::string(system) + ".mrk.json");
    write_slicer_markups(set, file, {system});
    const nlohmann::json json = nlohmann::json::parse(test::read_text(file));
    EXPECT_EQ(json["markups"][0]["coordinateSystem"], system);
    EXPECT_EQ(json["markups"][0]["type"], "Fiducial");
    const MarkupsReadResult back = read_slicer_markups(file);
    EXPECT_TRUE(back.notes.empty());
    ASSERT_EQ(back.landmarks.names(), set.names());
    for (std::size_t i = 0; i < set.landmarks.size(); ++i) {
      // Negation and shortest round-trip numbers: bit-exact.
      EXPECT_EQ(back.landmarks.landmarks[i].position_mm, set.landmarks[i].position_mm);
    }
  }
  EXPECT_THROW(write_slicer_markups(set, dir / "x.mrk.json", {"XYZ"}), InvalidInputError);
  EXPECT_THAT(io_error_of([&] { write_slicer_markups(set, dir / "no" / "such" / "x.mrk.json"); }),
              HasSubstr("x.mrk.json"));
}

TEST(SlicerMarkupsTest, ErrorsNameTheFileAndJsonPath) {
  const test::ScratchDir dir("markups");
  const auto error_for = [&](const std::string& body) {
    const auto file = test::write_file(dir / "bad.mrk.json", body);
    return io_error_of([&] { read_slicer_markups(file); });
  };
  const std::string path = (dir / "bad.mrk.json").string();
  EXPECT_THAT(error_for(R"({"markups": [{"type": "Fiducial", "controlPoints": [
                  {"label": "ankle", "position": [1, 2, 3]}, {"label": "b", "position": [1, 2]}]}]})"),
              AllOf(HasSubstr(path + ": markups[0].controlPoints[1].position"),
                    HasSubstr("must be 3 finite numbers, got [1,2]")));
  EXPECT_THAT(error_for(R"({"markups": [{"type": "Fiducial", "coordinateSystem": "XYZ"}]})"),
              HasSubstr("markups[0].coordinateSystem: must be \"LPS\" or \"RAS\", got \"XYZ\""));
  EXPECT_THAT(error_for(R"({"markups": [{"type": "Fiducial", "coordinateUnits": "inch"}]})"),
              HasSubstr("markups[0].coordinateUnits: must be \"mm\", \"um\" or \"m\""));
  EXPECT_THAT(error_for(R"({"markups": [{"type": "Line"}]})"), HasSubstr("holds no point list"));
  EXPECT_THAT(error_for(R"({"points": []})"), HasSubstr("field 'markups' must be an array"));
  EXPECT_THAT(error_for("{\"markups\": [}"), HasSubstr(path + ": not valid JSON"));
  EXPECT_THAT(error_for(R"({"markups": [{"type": "Fiducial", "controlPoints": [
                  {"label": "patella", "position": [1, 2, 3]},
                  {"label": "Patella Centre R", "position": [1, 2, 3]}]}]})"),
              HasSubstr("markups[0].controlPoints[1]: label 'Patella Centre R' gives landmark "
                        "'patella_centre_r', already given by markups[0].controlPoints[0]"));
  EXPECT_THAT(io_error_of([&] { read_slicer_markups(dir / "missing.mrk.json"); }),
              HasSubstr("missing.mrk.json: no such file"));
}

}  // namespace
}  // namespace mmm::landmarks

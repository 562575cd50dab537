#include "core/landmarks/landmark_set.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "core/errors.h"

namespace mmm::landmarks {
namespace {

using ::testing::HasSubstr;
using Json = nlohmann::json;

LandmarkSet example_set() {
  LandmarkSet set;
  set.frame = "patient";
  set.source = "radiographs";
  Landmark head;
  head.name = "femoral_head_centre_r";
  head.position_mm = {90.125, 0.1, 900.0 / 7.0};  // a number with no short decimal form
  head.pixels = {{"frontal", {812.5, 1003.25}}, {"lateral", {1010.0, 999.75}}};
  head.reprojection_error_mm = {{"frontal", 0.25}, {"lateral", 1.0 / 3.0}};
  Landmark patella;
  patella.name = "patella_centre_r";
  patella.position_mm = {80, 30, 480};
  set.landmarks = {head, patella};
  return set;
}

// The message of the InvalidInputError `parse` throws; "" when it throws nothing.
template <typename F>
std::string error_of(F&& parse) {
  try {
    parse();
  } catch (const InvalidInputError& error) {
    return error.what();
  }
  return {};
}

TEST(LandmarkSetTest, TextRoundTripIsExactAndCanonical) {
  const LandmarkSet set = example_set();
  const std::string text = landmark_set_to_json_text(set);
  const LandmarkSet back = landmark_set_from_json_text(text, "test");
  EXPECT_EQ(back.frame, "patient");
  EXPECT_EQ(back.source, "radiographs");
  ASSERT_EQ(back.names(), (std::vector<std::string>{"femoral_head_centre_r", "patella_centre_r"}));
  // Shortest round-trip numbers: bit-identical doubles.
  EXPECT_EQ(back.landmarks[0].position_mm, set.landmarks[0].position_mm);
  EXPECT_EQ(back.landmarks[0].pixels.at("lateral"), set.landmarks[0].pixels.at("lateral"));
  EXPECT_EQ(back.landmarks[0].reprojection_error_mm, set.landmarks[0].reprojection_error_mm);
  EXPECT_TRUE(back.landmarks[1].pixels.empty());
  // Canonical: the same set always gives the same text.
  EXPECT_EQ(landmark_set_to_json_text(back), text);
  // Optional maps are left out when empty.
  const Json json = Json::parse(text);
  EXPECT_FALSE(json["landmarks"][1].contains("pixels"));
  EXPECT_EQ(json["format"], "mmm-landmark-set");
  EXPECT_EQ(json["version"], 1);
}

TEST(LandmarkSetTest, NlohmannHooksConvertBothWays) {
  const Json json = example_set();
  const auto back = json.get<LandmarkSet>();
  EXPECT_EQ(back.find("patella_centre_r")->position_mm, Eigen::Vector3d(80, 30, 480));
  EXPECT_EQ(back.find("ankle_centre_r"), nullptr);
}

TEST(LandmarkSetTest, ErrorsNameTheLandmarkAndField) {
  Json json = example_set();
  json["landmarks"][1]["position_mm"] = {1, 2};
  EXPECT_THAT(error_of([&] { landmark_set_from_json_text(json.dump(), "study/landmarks.json"); }),
              HasSubstr("study/landmarks.json: landmarks[1] ('patella_centre_r'): field "
                        "'position_mm' must be 3 finite numbers, got [1,2]"));
  json = example_set();
  json["landmarks"][0]["pixels"]["frontal"] = {1, "a"};
  EXPECT_THAT(error_of([&] { landmark_set_from_json(json, "x"); }),
              HasSubstr("landmarks[0] ('femoral_head_centre_r'): field 'pixels.frontal' must be "
                        "2 finite numbers"));
  json = example_set();
  json["landmarks"][0]["reprojection_error_mm"]["lateral"] = -1;
  EXPECT_THAT(error_of([&] { landmark_set_from_json(json, "x"); }),
              HasSubstr("field 'reprojection_error_mm.lateral' must be a finite number >= 0"));
  json = example_set();
  json["landmarks"][1].erase("name");
  EXPECT_THAT(error_of([&] { landmark_set_from_json(json, "x"); }),
              HasSubstr("landmarks[1]: field 'name' is missing"));
  json = example_set();
  json["landmarks"][1]["name"] = "femoral_head_centre_r";
  EXPECT_THAT(error_of([&] { landmark_set_from_json(json, "x"); }),
              HasSubstr("name used twice (first at landmarks[0])"));
  json = example_set();
  json["version"] = 2;
  EXPECT_THAT(error_of([&] { landmark_set_from_json(json, "x"); }),
              HasSubstr("field 'version' must be 1"));
  json = example_set();
  json.erase("frame");
  EXPECT_THAT(error_of([&] { landmark_set_from_json(json, "x"); }),
              HasSubstr("field 'frame' is missing"));
}

TEST(LandmarkSetTest, NonFiniteNumbersAreRejected) {
  // JSON has no NaN: a writer that emits one produces invalid JSON.
  std::string text = landmark_set_to_json_text(example_set());
  text.replace(text.find("480"), 3, "NaN");
  EXPECT_THAT(error_of([&] { landmark_set_from_json_text(text, "x"); }),
              HasSubstr("not valid JSON"));
  // nlohmann writes a NaN as null: caught as a non-number.
  Json json = example_set();
  json["landmarks"][1]["position_mm"][2] = nullptr;
  EXPECT_THAT(error_of([&] { landmark_set_from_json(json, "x"); }),
              HasSubstr("'position_mm' must be 3 finite numbers"));
  // Writing refuses them rather than writing null.
  LandmarkSet set = example_set();
  set.landmarks[1].position_mm.y() = std::numeric_limits<double>::infinity();
  EXPECT_THAT(error_of([&] { landmark_set_to_json_text(set); }),
              HasSubstr("landmarks[1] ('patella_centre_r'): position_mm must be 3 finite"));
  set = example_set();
  set.landmarks[0].reprojection_error_mm["frontal"] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(error_of([&] { landmark_set_to_json_text(set); }),
              HasSubstr("reprojection_error_mm.frontal"));
}

}  // namespace
}  // namespace mmm::landmarks

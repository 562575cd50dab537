#include "core/image/outline_corrections.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"

namespace mmm::image {
namespace {

using ::testing::HasSubstr;
using Json = nlohmann::json;

const std::string kPairHash(64, 'a');
const std::string kAtlasHash(64, 'b');

OutlineCorrections two_corrections() {
  OutlineCorrections corrections;
  corrections.decision = OutlineDecision::kCorrect;
  corrections.corrections = {{"tibia_r", "lateral", {{10.5, 20.25}}},
                             {"femur_r", "lateral", {{1, 2}, {3, 4}}},
                             {"femur_r", "frontal", {{5, 6}}}};
  corrections.radiographs = kPairHash;
  corrections.atlas = kAtlasHash;
  return corrections;
}

std::string error_of(const std::string& text) {
  try {
    (void)read_outline_corrections(text, "verdict.json");
  } catch (const InvalidInputError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(OutlineCorrectionsTest, TheCanonicalTextRoundTripsSortedByBoneThenView) {
  OutlineCorrections corrections = two_corrections();
  sort_outline_corrections(corrections);
  ASSERT_EQ(corrections.corrections.size(), 3U);
  EXPECT_EQ(corrections.corrections[0].view, "frontal");
  EXPECT_EQ(corrections.corrections[2].bone, "tibia_r");
  const std::string text = outline_corrections_to_json_text(corrections);
  EXPECT_EQ(text.back(), '\n');
  const Json json = Json::parse(text);
  EXPECT_EQ(json["format"], "mmm-outline-corrections");
  EXPECT_EQ(json["version"], 1);
  EXPECT_EQ(json["decision"], "correct");
  EXPECT_EQ(json["corrections"][0]["points_px"], Json::parse("[[5.0, 6.0]]"));
  const OutlineCorrections read = read_outline_corrections(text, "verdict.json");
  EXPECT_EQ(read.decision, OutlineDecision::kCorrect);
  ASSERT_EQ(read.corrections.size(), 3U);
  EXPECT_EQ(read.corrections[1].bone, "femur_r");
  EXPECT_EQ(read.corrections[1].view, "lateral");
  EXPECT_EQ(read.corrections[1].points_px[1], Eigen::Vector2d(3, 4));
  EXPECT_EQ(read.corrections[2].points_px[0], Eigen::Vector2d(10.5, 20.25));
  EXPECT_EQ(read.radiographs, kPairHash);
  EXPECT_EQ(read.atlas, kAtlasHash);
  EXPECT_EQ(outline_corrections_to_json_text(read), text) << "canonical";
}

TEST(OutlineCorrectionsTest, AnAcceptedVerdictHasNoCorrections) {
  OutlineCorrections accepted;
  accepted.radiographs = kPairHash;
  accepted.atlas = kAtlasHash;
  const OutlineCorrections read =
      read_outline_corrections(outline_corrections_to_json_text(accepted), "verdict.json");
  EXPECT_EQ(read.decision, OutlineDecision::kAccept);
  EXPECT_TRUE(read.corrections.empty());
}

TEST(OutlineCorrectionsTest, ErrorsNameTheSourceAndTheField) {
  OutlineCorrections sorted = two_corrections();
  sort_outline_corrections(sorted);
  const Json good = Json::parse(outline_corrections_to_json_text(sorted));
  const auto changed = [&](const std::function<void(Json&)>& change) {
    Json json = good;
    change(json);
    return error_of(json.dump());
  };
  EXPECT_THAT(error_of("{"), HasSubstr("verdict.json: not valid JSON"));
  EXPECT_THAT(error_of("[]"), HasSubstr("must be a JSON object"));
  EXPECT_THAT(changed([](Json& j) { j["format"] = "other"; }), HasSubstr("format: must be"));
  EXPECT_THAT(changed([](Json& j) { j["version"] = 2; }), HasSubstr("version: must be 1"));
  EXPECT_THAT(changed([](Json& j) { j.erase("atlas"); }), HasSubstr("field 'atlas' is missing"));
  EXPECT_THAT(changed([](Json& j) { j["atlas"] = "xyz"; }),
              HasSubstr("atlas: must be an artifact"));
  EXPECT_THAT(changed([](Json& j) { j["decision"] = "maybe"; }),
              HasSubstr("decision: must be \"accept\" or \"correct\""));
  EXPECT_THAT(changed([](Json& j) { j["decision"] = "accept"; }),
              HasSubstr("corrections: must be empty"));
  EXPECT_THAT(changed([](Json& j) { j["corrections"] = Json::array(); }),
              HasSubstr("corrections: must not be empty"));
  EXPECT_THAT(changed([](Json& j) { j["extra"] = 1; }), HasSubstr("unknown field 'extra'"));
  EXPECT_THAT(changed([](Json& j) { j["corrections"][1]["points_px"][1] = {1}; }),
              HasSubstr("verdict.json: corrections[1].points_px[1]: must be [u, v]"));
  EXPECT_THAT(changed([](Json& j) { j["corrections"][0]["points_px"] = Json::array(); }),
              HasSubstr("corrections[0].points_px: must be a non-empty list"));
  EXPECT_THAT(changed([](Json& j) { j["corrections"][0]["bone"] = ""; }),
              HasSubstr("corrections[0]: field 'bone' must be a non-empty string"));
  EXPECT_THAT(changed([](Json& j) { j["corrections"][2]["bone"] = "a"; }),
              HasSubstr("corrections[2]: ('a', 'lateral') repeats or comes before"));
  EXPECT_THAT(changed([](Json& j) { j["corrections"][1] = j["corrections"][0]; }),
              HasSubstr("corrections[1]: ('femur_r', 'frontal') repeats"));
  EXPECT_THAT(changed([](Json& j) {
                Json many = Json::array();
                for (int k = 0; k < 201; ++k) many.push_back({1, 2});
                j["corrections"][0]["points_px"] = many;
              }),
              HasSubstr("holds 201 points, at most 200"));
  EXPECT_THAT(error_of(good.dump().replace(good.dump().find("5.0"), 3, "NaN")),
              HasSubstr("not valid JSON"));
  // The writer refuses what the reader would.
  OutlineCorrections unsorted = two_corrections();
  EXPECT_THROW((void)outline_corrections_to_json_text(unsorted), InvalidInputError);
}

}  // namespace
}  // namespace mmm::image

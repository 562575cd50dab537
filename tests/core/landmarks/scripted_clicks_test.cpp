// The scripted operator: without noise it clicks the ground truth's pixels
// exactly; with noise the offsets have the asked standard deviation and no
// bias, the same seed gives the same clicks; missing landmarks and bad noise
// are refused by name.

#include "core/landmarks/scripted_clicks.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace mmm::landmarks {
namespace {

nlohmann::json truth() {
  nlohmann::json t;
  t["landmarks"]["femoral_head_centre_r"]["pixels"] = {{"frontal", {100.0, 200.0}},
                                                       {"lateral", {300.0, 210.0}}};
  t["landmarks"]["patella_centre_r"]["pixels"] = {{"frontal", {120.0, 900.0}},
                                                  {"lateral", {280.0, 905.0}}};
  return t;
}

TEST(ScriptedClicks, WithoutNoiseAreTheGroundTruthPixels) {
  ScriptedClickOptions options;
  options.landmarks = {"femoral_head_centre_r", "patella_centre_r"};
  options.noise_px = 0.0;
  const nlohmann::json clicks = scripted_clicks(truth(), options);
  EXPECT_EQ(clicks["landmarks"]["femoral_head_centre_r"]["lateral"][0].get<double>(), 300.0);
  EXPECT_EQ(clicks["landmarks"]["patella_centre_r"]["frontal"][1].get<double>(), 900.0);
  EXPECT_EQ(clicks["landmarks"].size(), 2U);
}

TEST(ScriptedClicks, NoiseHasTheAskedSpreadAndIsRepeatable) {
  ScriptedClickOptions options;
  options.landmarks = {"femoral_head_centre_r", "patella_centre_r"};
  options.noise_px = 2.0;
  double sum = 0.0;
  double squares = 0.0;
  int count = 0;
  for (std::uint64_t seed = 1; seed <= 500; ++seed) {
    options.seed = seed;
    const nlohmann::json clicks = scripted_clicks(truth(), options);
    for (const auto& [name, views] : clicks["landmarks"].items()) {
      for (const auto& [view, pixel] : views.items()) {
        for (int c = 0; c < 2; ++c) {
          const double d =
              pixel[c].get<double>() - truth()["landmarks"][name]["pixels"][view][c].get<double>();
          sum += d;
          squares += d * d;
          ++count;
        }
      }
    }
  }
  // 4000 draws: the mean within 4 standard errors (0.13 px), the spread within 5 %.
  EXPECT_LT(std::abs(sum / count), 4.0 * 2.0 / std::sqrt(count));
  EXPECT_NEAR(std::sqrt(squares / count), 2.0, 0.1);
  options.seed = 7;
  EXPECT_EQ(scripted_clicks(truth(), options), scripted_clicks(truth(), options));
}

TEST(ScriptedClicks, MissingLandmarksAndBadNoiseAreRefused) {
  ScriptedClickOptions options;  // asks for the ankle too, which truth() lacks
  try {
    (void)scripted_clicks(truth(), options);
    FAIL() << "the missing ankle was not noticed";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("ankle_centre_r"), std::string::npos);
  }
  options.landmarks = {"patella_centre_r"};
  options.noise_px = -1.0;
  EXPECT_THROW((void)scripted_clicks(truth(), options), InvalidInputError);
  EXPECT_THROW((void)scripted_clicks(nlohmann::json::object(), ScriptedClickOptions{}),
               InvalidInputError);
}

}  // namespace
}  // namespace mmm::landmarks

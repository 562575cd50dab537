#include "core/landmarks/landmark_labels.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>

#include "core/atlas/atlas_recipe.h"
#include "tests/support/test_data.h"

namespace mmm::landmarks {
namespace {

using ::testing::HasSubstr;

TEST(LandmarkLabelsTest, CommonLabelsNameTheirAtlasLandmark) {
  const std::map<std::string, std::string> expected = {
      {"RASIS", "asis_r"},
      {"R ASIS", "asis_r"},
      {"Right ASIS", "asis_r"},
      {"r.asis", "asis_r"},
      {"LASIS", "asis_l"},
      {"L ASIS", "asis_l"},
      {"Left ASIS", "asis_l"},
      {"Lateral Epicondyle R", "lateral_epicondyle_r"},
      {"RLE", "lateral_epicondyle_r"},
      {"R Knee Lat", "lateral_epicondyle_r"},
      {"R.Knee.Lat", "lateral_epicondyle_r"},
      {"medial epicondyle", "medial_epicondyle_r"},
      {"R_Knee_Med", "medial_epicondyle_r"},
      {"Lateral Malleolus Right", "lateral_malleolus_r"},
      {"R Ankle Med", "medial_malleolus_r"},
      {"RMM", "medial_malleolus_r"},
      {"Heel", "heel_r"},
      {"R Calcaneus", "heel_r"},
      {"Femoral Head Center R", "femoral_head_centre_r"},
      {"hip centre", "femoral_head_centre_r"},
      {"RHJC", "femoral_head_centre_r"},
      {"Patella Centre", "patella_centre_r"},
      {"Ankle Center", "ankle_centre_r"},
      {"Knee Centre R", "knee_centre_r"},
      {"V Sacral", "sacral_point"},
      {"V.Sacral", "sacral_point"},
      {"Sacrum", "sacral_point"},
      {"heel_r", "heel_r"},
      {"ASIS_L", "asis_l"}};
  for (const auto& [label, name] : expected) {
    EXPECT_EQ(landmark_for_label(label), name) << label;
  }
  // An ASIS needs its side; nonsense and empty labels name nothing.
  EXPECT_EQ(landmark_for_label("ASIS"), "");
  EXPECT_EQ(landmark_for_label("lesser trochanter"), "");
  EXPECT_EQ(landmark_for_label(" _ "), "");
}

TEST(LandmarkLabelsTest, NoLabelNamesTwoLandmarks) {
  std::map<std::string, std::string> owner;
  for (const LandmarkLabels& entry : landmark_label_table()) {
    for (const std::string& label : normalised_labels(entry)) {
      const auto [it, inserted] = owner.emplace(label, entry.name);
      EXPECT_TRUE(inserted) << "'" << label << "' names " << it->second << " and " << entry.name;
    }
  }
}

TEST(LandmarkLabelsTest, TheRecipeDescriptionsAreTheDefinitions) {
  // The default atlas's manifest carries the recipe's descriptions; the
  // station and the import show the table's: they must be the same text.
  const atlas::AtlasRecipe recipe =
      atlas::read_atlas_recipe(test::source_dir() / "schemas/recipes/vhf_right_leg.yaml");
  int checked = 0;
  for (const atlas::RecipeLandmark& landmark : recipe.landmarks) {
    EXPECT_EQ(landmark.description, landmark_definition(landmark.name)) << landmark.name;
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(landmark_label_table().size()));
}

TEST(LandmarkLabelsTest, TableTextListsNamesLabelsAndDefinitions) {
  const std::string text = landmark_label_table_text();
  EXPECT_THAT(text, HasSubstr("asis_r (R ASIS"));
  EXPECT_THAT(text, HasSubstr("lateral_epicondyle_r ("));
  EXPECT_THAT(text, HasSubstr("Lateral femoral epicondyle: the most prominent point"));
  EXPECT_THAT(landmark_definition("femoral_head_centre_l"), HasSubstr("left femoral head"));
  EXPECT_EQ(landmark_definition("no_such_landmark"), "");
}

}  // namespace
}  // namespace mmm::landmarks

#include "core/motion/marker_mapping.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/opensim/marker_set.h"
#include "tests/support/test_data.h"

namespace mmm::motion {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_marker_mapping(text, "mapping.yaml");
  } catch (const IoError& error) {
    return error.what();
  }
  return "";
}

TEST(MarkerMappingTest, ShippedGait2392MappingHasOpenSimsIkWeights) {
  const MarkerMapping mapping = gait2392_marker_mapping();
  EXPECT_EQ(mapping.name, "gait2392");
  const auto weights = opensim::read_ik_task_weights(test::data_dir() / "gait2392" / "Pipelines" /
                                                     "subject01_Setup_IK.xml");
  std::size_t applied = 0;
  for (const auto& [name, task] : weights) applied += task.apply ? 1 : 0;
  ASSERT_EQ(mapping.markers.size(), applied);
  for (const MarkerTask& task : mapping.markers) {
    ASSERT_TRUE(weights.contains(task.trial)) << task.trial;
    EXPECT_DOUBLE_EQ(task.weight, weights.at(task.trial).weight) << task.trial;
    EXPECT_EQ(task.model, task.trial);
  }
  ASSERT_EQ(mapping.coordinates.size(), 4u);
  EXPECT_EQ(mapping.coordinates.front().coordinate, "subtalar_angle_r");
  EXPECT_DOUBLE_EQ(mapping.coordinates.front().weight, 1000.0);
}

TEST(MarkerMappingTest, ReadsRenamesAndDefaults) {
  const MarkerMapping mapping = parse_marker_mapping(
      "mmm_marker_mapping: 1\nmarkers:\n  - {trial: RASI, model: R.ASIS, weight: 10}\n"
      "  - {trial: LASI, model: L.ASIS}\n",
      "lab.yaml");
  ASSERT_EQ(mapping.markers.size(), 2u);
  EXPECT_EQ(mapping.markers[0].model, "R.ASIS");
  EXPECT_DOUBLE_EQ(mapping.markers[1].weight, 1.0);
  EXPECT_TRUE(mapping.coordinates.empty());
}

TEST(MarkerMappingTest, BadFilesNameTheLineFieldAndAHint) {
  EXPECT_NE(error_of("markers: [").find("malformed YAML"), std::string::npos);
  EXPECT_NE(error_of("mmm_marker_mapping: 2\nmarkers: [{trial: A}]").find("must be 1"),
            std::string::npos);
  const std::string typo = error_of("mmm_marker_mapping: 1\nmarker: [{trial: A}]");
  EXPECT_NE(typo.find("did you mean 'markers'"), std::string::npos) << typo;
  const std::string weight =
      error_of("mmm_marker_mapping: 1\nmarkers:\n  - {trial: A, weight: -1}\n");
  EXPECT_NE(weight.find("line 3"), std::string::npos) << weight;
  EXPECT_NE(weight.find("markers[0].weight"), std::string::npos) << weight;
  EXPECT_NE(error_of("mmm_marker_mapping: 1\nmarkers: [{trial: A}, {trial: A}]").find("twice"),
            std::string::npos);
  EXPECT_NE(
      error_of("mmm_marker_mapping: 1\nmarkers: [{trial: A, weight: 0}]").find("every weight"),
      std::string::npos);
  EXPECT_NE(error_of("mmm_marker_mapping: 1\nmarkers: [{model: A}]").find("trial: is required"),
            std::string::npos);
  EXPECT_THROW(read_marker_mapping("/nonexistent/mapping.yaml"), IoError);
}

}  // namespace
}  // namespace mmm::motion

// check_landmark_anatomy (landmark_validation.h): the checks of 3-D
// landmarks that did not come from the station, and the mirrored-file hint.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/landmarks/landmark_validation.h"

namespace mmm::landmarks {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

// The default atlas's landmarks (VHF, RAS, mm), rounded: a right file.
LandmarkSet atlas_landmarks() {
  LandmarkSet set;
  set.source = "slicer_markups";
  const std::vector<std::pair<std::string, Eigen::Vector3d>> points = {
      {"femoral_head_centre_r", {637.1, 448.8, 882.9}},
      {"patella_centre_r", {637.9, 475.9, 513.0}},
      {"ankle_centre_r", {583.3, 407.5, 143.8}},
      {"knee_centre_r", {618.7, 422.0, 511.0}},
      {"asis_r", {677.4, 491.3, 975.8}},
      {"asis_l", {400.1, 497.5, 978.7}},
      {"sacral_point", {535.7, 350.6, 961.5}},
      {"lateral_epicondyle_r", {656.1, 419.6, 504.3}},
      {"medial_epicondyle_r", {578.2, 433.1, 505.2}},
      {"lateral_malleolus_r", {616.9, 395.9, 155.2}},
      {"medial_malleolus_r", {571.3, 413.4, 171.8}},
      {"heel_r", {575.7, 355.3, 142.1}}};
  for (const auto& [name, position] : points) set.landmarks.push_back({name, position, {}, {}});
  return set;
}

LandmarkSet negate_x_and_y(LandmarkSet set) {
  for (Landmark& landmark : set.landmarks) {
    landmark.position_mm.x() = -landmark.position_mm.x();
    landmark.position_mm.y() = -landmark.position_mm.y();
  }
  return set;
}

TEST(LandmarkAnatomyTest, TheAtlasLandmarksPass) {
  EXPECT_THAT(check_landmark_anatomy(atlas_landmarks()), IsEmpty());
}

TEST(LandmarkAnatomyTest, LpsPointsDeclaredRasAreRejectedWithTheHint) {
  const std::vector<std::string> reasons =
      check_landmark_anatomy(negate_x_and_y(atlas_landmarks()));
  ASSERT_FALSE(reasons.empty());
  EXPECT_THAT(reasons.front(), HasSubstr("'asis_r' should lie in front of"));
  EXPECT_THAT(reasons.back(), AllOf(HasSubstr("the points look like LPS coordinates read as RAS"),
                                    HasSubstr("set the point list's coordinateSystem to \"LPS\"")));
  // The same file declared LPS (so RAS points were negated on reading).
  AnatomyRules rules;
  rules.declared_coordinate_system = "LPS";
  EXPECT_THAT(check_landmark_anatomy(negate_x_and_y(atlas_landmarks()), rules).back(),
              HasSubstr("coordinateSystem to \"RAS\""));
}

TEST(LandmarkAnatomyTest, TheStationsThreeAloneStillRevealAMirroredFile) {
  LandmarkSet three;
  for (const Landmark& landmark : atlas_landmarks().landmarks) {
    if (landmark.name == "femoral_head_centre_r" || landmark.name == "patella_centre_r" ||
        landmark.name == "ankle_centre_r") {
      three.landmarks.push_back(landmark);
    }
  }
  EXPECT_THAT(check_landmark_anatomy(three), IsEmpty());
  EXPECT_THAT(check_landmark_anatomy(negate_x_and_y(three)).back(), HasSubstr("look like LPS"));
}

TEST(LandmarkAnatomyTest, OneMisplacedPointIsNamedWithoutTheMirrorHint) {
  LandmarkSet set = atlas_landmarks();
  // The epicondyles swapped.
  std::swap(set.landmarks[7].position_mm, set.landmarks[8].position_mm);
  const std::vector<std::string> reasons = check_landmark_anatomy(set);
  ASSERT_EQ(reasons.size(), 1U);
  EXPECT_THAT(reasons[0], HasSubstr("'lateral_epicondyle_r' should lie lateral of"));
  // Heights and distances: the patella above the head, the ASIS 400 mm apart.
  set = atlas_landmarks();
  set.landmarks[1].position_mm.z() = 950.0;
  set.landmarks[5].position_mm.x() = 270.0;
  const std::vector<std::string> more = check_landmark_anatomy(set);
  EXPECT_THAT(more, testing::Contains(HasSubstr("'femoral_head_centre_r' (z = 882.9 mm) should be "
                                                "above 'patella_centre_r'")));
  EXPECT_THAT(more, testing::Contains(HasSubstr("from 'asis_r' to 'asis_l' is 407.5 mm")));
  EXPECT_THROW(check_landmark_anatomy(set, AnatomyRules{.side = "up"}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::landmarks

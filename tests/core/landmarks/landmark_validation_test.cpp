#include "core/landmarks/landmark_validation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "core/errors.h"

namespace mmm::landmarks {
namespace {

using image::RadiographView;
using ::testing::AllOf;
using ::testing::Each;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

// A standing adult's right leg, the sagittal midline at x = 0, the field
// (default 450 x 1100 mm) centred at knee height on the midline.
constexpr double kIsocentreZ = 500.0;
const Eigen::Vector3d kHead(90, 0, 900);
const Eigen::Vector3d kPatella(80, 30, 480);
const Eigen::Vector3d kAnkle(75, 0, 80);

std::array<RadiographView, 2> leg_views() {
  image::BiplanarOptions options;
  options.isocentre_mm = {0, 0, kIsocentreZ};
  return image::make_biplanar_views(options);
}

// Exact pixels of the given points in both views.
PixelSubmission submit(std::span<const RadiographView> views,
                       const std::map<std::string, Eigen::Vector3d>& points) {
  PixelSubmission submission;
  for (const auto& [name, X] : points) {
    for (const RadiographView& view : views) submission[name][view.name] = image::project(view, X);
  }
  return submission;
}

PixelSubmission good_submission(std::span<const RadiographView> views) {
  return submit(views, {{"femoral_head_centre_r", kHead},
                        {"patella_centre_r", kPatella},
                        {"ankle_centre_r", kAnkle}});
}

TEST(LandmarkValidationTest, CentralRaysCrossAtTheIsocentre) {
  image::BiplanarOptions options;
  options.isocentre_mm = {-12.5, 40, 700};
  const auto views = image::make_biplanar_views(options);
  // The isocentre projects to both image centres: exact up to rounding.
  EXPECT_NEAR(central_ray_crossing_x(views), -12.5, 1e-6);
  const std::array<RadiographView, 2> twice = {views[0], views[0]};
  EXPECT_THROW(central_ray_crossing_x(twice), InvalidInputError);
}

TEST(LandmarkValidationTest, ConsistentSubmissionIsAcceptedAndTriangulated) {
  const auto views = leg_views();
  const ValidationResult result = validate_submission(views, good_submission(views));
  EXPECT_THAT(result.reasons, IsEmpty());
  EXPECT_TRUE(result.accepted());
  EXPECT_NEAR(result.midline_x_mm, 0.0, 1e-6);  // the isocentre's x, up to rounding
  ASSERT_TRUE(result.landmarks.has_value());
  const LandmarkSet& set = *result.landmarks;
  EXPECT_EQ(set.frame, "patient");
  EXPECT_EQ(set.source, "radiographs");
  // Required first, then optional.
  EXPECT_THAT(set.names(),
              ElementsAre("femoral_head_centre_r", "patella_centre_r", "ankle_centre_r"));
  // Exact pixels: rounding only.
  EXPECT_LT((set.find("patella_centre_r")->position_mm - kPatella).norm(), 1e-6);
  const Landmark& head = *set.find("femoral_head_centre_r");
  EXPECT_LT((head.position_mm - kHead).norm(), 1e-6);
  ASSERT_EQ(head.pixels.size(), 2U);
  EXPECT_EQ(head.pixels.at("lateral"), image::project(views[1], kHead));
  EXPECT_LT(head.reprojection_error_mm.at("frontal"), 1e-6);
  EXPECT_NO_THROW(validate_landmark_set(set));
}

TEST(LandmarkValidationTest, OptionalLandmarkMayBeLeftOut) {
  const auto views = leg_views();
  PixelSubmission submission = good_submission(views);
  submission.erase("ankle_centre_r");
  EXPECT_THAT(validate_submission(views, submission).reasons, IsEmpty());
}

TEST(LandmarkValidationTest, MissingRequiredLandmark) {
  const auto views = leg_views();
  PixelSubmission submission = good_submission(views);
  submission.erase("patella_centre_r");
  const ValidationResult result = validate_submission(views, submission);
  EXPECT_THAT(result.reasons, ElementsAre("Required landmark 'patella_centre_r' is missing."));
  // The others are still triangulated.
  ASSERT_TRUE(result.landmarks.has_value());
  EXPECT_THAT(result.landmarks->names(), ElementsAre("femoral_head_centre_r", "ankle_centre_r"));
}

TEST(LandmarkValidationTest, UnknownLandmarkNameSuggestsTheClosest) {
  const auto views = leg_views();
  PixelSubmission submission = good_submission(views);
  submission["patela_centre_r"] = submission["patella_centre_r"];
  const ValidationResult result = validate_submission(views, submission);
  ASSERT_EQ(result.reasons.size(), 1U);
  EXPECT_THAT(result.reasons[0],
              AllOf(HasSubstr("Landmark 'patela_centre_r' is not one this task asks for"),
                    HasSubstr("did you mean 'patella_centre_r'?"),
                    HasSubstr("expected: femoral_head_centre_r, patella_centre_r, "
                              "ankle_centre_r")));
}

TEST(LandmarkValidationTest, UnknownViewName) {
  const auto views = leg_views();
  PixelSubmission submission = good_submission(views);
  submission["patella_centre_r"]["frontl"] = {10, 10};
  const ValidationResult result = validate_submission(views, submission);
  ASSERT_EQ(result.reasons.size(), 1U);
  EXPECT_THAT(result.reasons[0], AllOf(HasSubstr("'patella_centre_r' is given in view 'frontl'"),
                                       HasSubstr("did you mean 'frontal'?")));
}

TEST(LandmarkValidationTest, LandmarkMissingInAView) {
  const auto views = leg_views();
  PixelSubmission submission = good_submission(views);
  submission["ankle_centre_r"].erase("lateral");
  const ValidationResult result = validate_submission(views, submission);
  EXPECT_THAT(result.reasons,
              ElementsAre("Landmark 'ankle_centre_r' is missing in view 'lateral'."));
  // One view cannot place it in 3-D.
  EXPECT_EQ(result.landmarks->find("ankle_centre_r"), nullptr);
}

TEST(LandmarkValidationTest, NonFinitePixel) {
  const auto views = leg_views();
  PixelSubmission submission = good_submission(views);
  submission["femoral_head_centre_r"]["frontal"].y() = std::numeric_limits<double>::quiet_NaN();
  const ValidationResult result = validate_submission(views, submission);
  EXPECT_THAT(result.reasons,
              ElementsAre("Landmark 'femoral_head_centre_r' in view 'frontal' has a pixel "
                          "position that is not a finite number."));
}

TEST(LandmarkValidationTest, PixelOutsideTheImage) {
  const auto views = leg_views();
  // An ankle 150 mm lower than the field reaches (its bottom is at z = -50
  // at the isocentre): still a plausible leg, but the operator cannot have
  // seen it.
  const Eigen::Vector3d low_ankle(75, 0, -100);
  const PixelSubmission submission = submit(views, {{"femoral_head_centre_r", kHead},
                                                    {"patella_centre_r", kPatella},
                                                    {"ankle_centre_r", low_ankle}});
  const ValidationResult result = validate_submission(views, submission);
  ASSERT_EQ(result.reasons.size(), 2U);
  EXPECT_THAT(result.reasons[0], HasSubstr("Landmark 'ankle_centre_r' in view 'frontal' is at "
                                           "pixel"));
  const std::string image = "outside the image [0, " + std::to_string(views[0].width) + "] x [0, " +
                            std::to_string(views[0].height) + "]";
  EXPECT_THAT(result.reasons, Each(HasSubstr(image)));
  EXPECT_THAT(result.reasons[1], HasSubstr("in view 'lateral'"));
}

TEST(LandmarkValidationTest, ReprojectionErrorAboveTolerance) {
  const auto views = leg_views();
  PixelSubmission submission = good_submission(views);
  // The patella clicked 40 pixels (9.2 mm at the isocentre) lower in the
  // frontal view than in the lateral one: the heights disagree, and the fit
  // leaves about half of it in each view (4.8 mm frontal, 4.6 mm lateral:
  // the patella lies 80 mm nearer the lateral source than the isocentre,
  // so the lateral view magnifies its height more and weighs a little more).
  submission["patella_centre_r"]["frontal"].y() += 40;
  const ValidationResult result = validate_submission(views, submission);
  ASSERT_EQ(result.reasons.size(), 2U);
  EXPECT_THAT(result.reasons[0],
              AllOf(HasSubstr("Landmark 'patella_centre_r' in view 'frontal': reprojection "
                              "error 4.8 mm exceeds the tolerance of 3.0 mm")));
  EXPECT_THAT(result.reasons[1], HasSubstr("'patella_centre_r' in view 'lateral'"));
  // Still triangulated, with the errors recorded.
  EXPECT_GT(result.landmarks->find("patella_centre_r")->reprojection_error_mm.at("frontal"), 3.0);
  // A looser tolerance accepts it.
  ValidationRules rules;
  rules.reprojection_tolerance_mm = 5.0;
  EXPECT_THAT(validate_submission(views, submission, rules).reasons, IsEmpty());
}

TEST(LandmarkValidationTest, LandmarksOutOfVerticalOrder) {
  const auto views = leg_views();
  // The ankle placed above the patella, at a plausible distance from it.
  const PixelSubmission submission = submit(views, {{"femoral_head_centre_r", kHead},
                                                    {"patella_centre_r", kPatella},
                                                    {"ankle_centre_r", {75, 0, 870}}});
  const ValidationResult result = validate_submission(views, submission);
  ASSERT_EQ(result.reasons.size(), 1U);
  EXPECT_THAT(result.reasons[0], HasSubstr("Landmark 'patella_centre_r' (z = 480.0 mm) should be "
                                           "above 'ankle_centre_r' (z = 870.0 mm)"));
}

TEST(LandmarkValidationTest, DistanceOutOfAnatomicalRange) {
  const auto views = leg_views();
  // A shank of 18 cm: the ankle clicked at mid-shin.
  const PixelSubmission submission = submit(views, {{"femoral_head_centre_r", kHead},
                                                    {"patella_centre_r", kPatella},
                                                    {"ankle_centre_r", {75, 0, 300}}});
  const ValidationResult result = validate_submission(views, submission);
  ASSERT_EQ(result.reasons.size(), 1U);
  EXPECT_THAT(result.reasons[0],
              HasSubstr("Distance from 'patella_centre_r' to 'ankle_centre_r' is 182.6 mm, "
                        "outside the adult range [270.0, 620.0] mm."));
}

TEST(LandmarkValidationTest, LandmarksOfTheOtherLeg) {
  const auto views = leg_views();
  // The left leg clicked: the mirror image of the right one.
  const Eigen::Vector3d mirror(-1, 1, 1);
  const PixelSubmission submission =
      submit(views, {{"femoral_head_centre_r", kHead.cwiseProduct(mirror)},
                     {"patella_centre_r", kPatella.cwiseProduct(mirror)},
                     {"ankle_centre_r", kAnkle.cwiseProduct(mirror)}});
  const ValidationResult result = validate_submission(views, submission);
  ASSERT_EQ(result.reasons.size(), 3U);
  EXPECT_THAT(result.reasons[0],
              HasSubstr("Landmark 'femoral_head_centre_r' lies 90.0 mm to the subject's left of "
                        "the midline (x = 0.0 mm); a landmark of the right leg must lie at least "
                        "10.0 mm to the subject's right"));
  EXPECT_THAT(result.reasons, Each(HasSubstr("to the subject's left of the midline")));
  // The same points are right for a left-leg task (names aside).
  ValidationRules rules;
  rules.side = "left";
  EXPECT_THAT(validate_submission(views, submission, rules).reasons, IsEmpty());
  // A midline moved 150 mm to the left puts them on the right of it again.
  rules.side = "right";
  rules.midline_x_mm = -150.0;
  EXPECT_THAT(validate_submission(views, submission, rules).reasons, IsEmpty());
}

TEST(LandmarkValidationTest, EveryProblemIsListed) {
  const auto views = leg_views();
  PixelSubmission submission = good_submission(views);
  submission.erase("patella_centre_r");                         // required missing
  submission["ankel_centre_r"] = submission["ankle_centre_r"];  // unknown name
  submission["ankle_centre_r"].erase("frontal");                // missing in a view
  submission["femoral_head_centre_r"]["lateral"].y() += 60;     // views disagree
  const ValidationResult result = validate_submission(views, submission);
  EXPECT_EQ(result.reasons.size(), 5U) << ::testing::PrintToString(result.reasons);
}

TEST(LandmarkValidationTest, SyntheticPatientGeometryIsAccepted) {
  // The geometry of a synthetic patient (core/atlas/synthetic_patient.h,
  // VHF atlas, seed 1, 1 mm detector pitch): the field centred on the
  // bones' bounding box, which holds both hip bones and the right leg, so
  // that the isocentre lies ~8 mm right of the midline. Landmarks and view
  // geometry copied from its ground_truth.json and views.json.
  image::BiplanarOptions options;
  options.isocentre_mm = {544.5428854857446, 428.7910253836571, 512.8361891836844};
  options.detector_pixel_pitch_mm = 1.0;
  options.field_width_mm = 547 * 1.0 * 1300.0 / 1700.0;
  options.field_height_mm = 1480 * 1.0 * 1300.0 / 1700.0;
  const auto views = image::make_biplanar_views(options);
  ASSERT_EQ(views[0].width, 547);
  ASSERT_EQ(views[0].height, 1480);
  const PixelSubmission submission = submit(
      views, {{"femoral_head_centre_r", {638.1200332805704, 450.43324486618536, 884.72742106746}},
              {"patella_centre_r", {639.4061380657, 476.9411314873698, 542.7054094433637}},
              {"ankle_centre_r", {585.9203119807182, 410.90437787075837, 170.71805080875893}}});
  const ValidationResult result = validate_submission(views, submission);
  EXPECT_THAT(result.reasons, IsEmpty());
  EXPECT_NEAR(result.midline_x_mm, 544.5428854857446, 1e-6);  // rounding
  // The pixels the synthetic patient recorded for the femoral head (frontal).
  const Landmark& head = *result.landmarks->find("femoral_head_centre_r");
  EXPECT_NEAR(head.pixels.at("frontal").x(), 149.05819374228034, 1e-6);
  EXPECT_NEAR(head.pixels.at("frontal").y(), 245.44745466601555, 1e-6);
}

TEST(LandmarkValidationTest, BadRulesOrViewsThrow) {
  const auto views = leg_views();
  const PixelSubmission submission = good_submission(views);
  ValidationRules rules;
  rules.side = "up";
  EXPECT_THROW(validate_submission(views, submission, rules), InvalidInputError);
  rules = {};
  rules.reprojection_tolerance_mm = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(validate_submission(views, submission, rules), InvalidInputError);
  rules = {};
  rules.distances.push_back({"a", "b", 10, 5});
  EXPECT_THROW(validate_submission(views, submission, rules), InvalidInputError);
  EXPECT_THROW(validate_submission(std::span(views).first(1), submission), InvalidInputError);
  const std::array<RadiographView, 2> same_name = {views[0], views[0]};
  EXPECT_THROW(validate_submission(same_name, submission), InvalidInputError);
}

}  // namespace
}  // namespace mmm::landmarks

namespace mmm::landmarks {
namespace {

// The pelvis's landmarks of a right-leg task: the left ASIS belongs to the
// left of the midline, and swapping the two ASIS is caught.
TEST(LandmarkValidationTest, TheOtherSidesAsisBelongsOnTheOtherSide) {
  const auto views = leg_views();
  ValidationRules rules;
  rules.required.emplace_back("asis_r");
  rules.required.emplace_back("asis_l");
  rules.opposite_side = {"asis_l"};
  const Eigen::Vector3d asis_r(120, 60, 960);
  const Eigen::Vector3d asis_l(-120, 60, 960);
  const ValidationResult accepted =
      validate_submission(views,
                          submit(views, {{"femoral_head_centre_r", kHead},
                                         {"patella_centre_r", kPatella},
                                         {"ankle_centre_r", kAnkle},
                                         {"asis_r", asis_r},
                                         {"asis_l", asis_l}}),
                          rules);
  EXPECT_THAT(accepted.reasons, IsEmpty());
  const ValidationResult swapped =
      validate_submission(views,
                          submit(views, {{"femoral_head_centre_r", kHead},
                                         {"patella_centre_r", kPatella},
                                         {"ankle_centre_r", kAnkle},
                                         {"asis_r", asis_l},
                                         {"asis_l", asis_r}}),
                          rules);
  EXPECT_THAT(swapped.reasons, Contains(HasSubstr("a landmark of the other side must lie at least "
                                                  "10.0 mm to the subject's left (the two sides "
                                                  "swapped?)")))
      << ::testing::PrintToString(swapped.reasons);
}

}  // namespace
}  // namespace mmm::landmarks

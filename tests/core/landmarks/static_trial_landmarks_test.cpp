#include "core/landmarks/static_trial_landmarks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/opensim/osim_model.h"
#include "tests/support/test_data.h"

namespace mmm::landmarks {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A trial with `frames` identical frames of the given markers (positions in
// the file's units).
opensim::MarkerTrajectories make_trial(
    const std::vector<std::pair<std::string, Eigen::Vector3d>>& markers, int frames,
    const std::string& units = "mm", double unit_to_mm = 1.0) {
  opensim::MarkerTrajectories trial;
  trial.source = "static.trc";
  trial.data_rate = 60;
  trial.units = units;
  trial.unit_to_mm = unit_to_mm;
  trial.positions.resize(frames, 3 * static_cast<Eigen::Index>(markers.size()));
  trial.times.resize(frames);
  for (int f = 0; f < frames; ++f) {
    trial.frame_numbers.push_back(f + 1);
    trial.times(f) = f / 60.0;
    for (std::size_t m = 0; m < markers.size(); ++m) {
      trial.positions.block<1, 3>(f, 3 * static_cast<Eigen::Index>(m)) =
          markers[m].second.transpose();
    }
  }
  for (const auto& [name, position] : markers) trial.marker_names.push_back(name);
  return trial;
}

// Lab axes as in gait2392's trials: x forward, y up, z to the subject's
// right. A pelvis 250 mm wide (ASIS to ASIS) and 160 mm deep (ASIS midpoint
// to sacral marker), level, facing +x.
std::vector<std::pair<std::string, Eigen::Vector3d>> symmetric_markers() {
  return {{"R.ASIS", {100, 1000, 125}},   {"L.ASIS", {100, 1000, -125}},
          {"V.Sacral", {-60, 1000, 0}},   {"R.Knee.Lat", {10, 500, 140}},
          {"R.Knee.Med", {10, 500, 40}},  {"L.Knee.Lat", {10, 500, -140}},
          {"L.Knee.Med", {10, 500, -40}}, {"R.Ankle.Lat", {-10, 80, 100}},
          {"R.Ankle.Med", {-10, 80, 40}}, {"L.Ankle.Lat", {-10, 80, -100}},
          {"L.Ankle.Med", {-10, 80, -40}}};
}

// By hand from Harrington et al. 2007 with PW = 250, PD = 160:
//   anterior -0.24 * 160 - 9.9 = -48.3, superior -0.30 * 250 - 10.9 = -85.9,
//   lateral 0.33 * 250 + 7.3 = 89.8 (mm), from the ASIS midpoint (100, 1000, 0).
const Eigen::Vector3d kHipRight(51.7, 914.1, 89.8);
const Eigen::Vector3d kHipLeft(51.7, 914.1, -89.8);

TEST(StaticTrialTest, HarringtonRegressionByHand) {
  const HarringtonHipCentres hips =
      harrington_hip_centres({100, 1000, 125}, {100, 1000, -125}, {-60, 1000, 0});
  EXPECT_DOUBLE_EQ(hips.pelvis_width_mm, 250.0);
  EXPECT_DOUBLE_EQ(hips.pelvis_depth_mm, 160.0);
  // Sums of a few products of numbers ~1e3: rounding ~1e-12.
  EXPECT_LT((hips.right - kHipRight).norm(), 1e-9);
  EXPECT_LT((hips.left - kHipLeft).norm(), 1e-9);
}

TEST(StaticTrialTest, HarringtonFollowsThePelvis) {
  // Rotating and moving the markers moves the hip centres with them.
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const Eigen::Vector3d t(-300, 25, 1200);
  const auto move = [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(R * p + t); };
  const HarringtonHipCentres hips =
      harrington_hip_centres(move({100, 1000, 125}), move({100, 1000, -125}), move({-60, 1000, 0}));
  EXPECT_LT((hips.right - move(kHipRight)).norm(), 1e-9);  // rounding, as above
  EXPECT_LT((hips.left - move(kHipLeft)).norm(), 1e-9);
  EXPECT_THROW(harrington_hip_centres({0, 0, 1}, {0, 0, 1}, {-1, 0, 0}), InvalidInputError);
  EXPECT_THROW(harrington_hip_centres({0, 0, 1}, {0, 0, -1}, {0, 0, 3}), InvalidInputError);
}

TEST(StaticTrialTest, MidpointsAndHipCentresOfASymmetricSubject) {
  const StaticTrialResult result = landmarks_from_static_trial(make_trial(symmetric_markers(), 20));
  const LandmarkSet& set = result.landmarks;
  EXPECT_EQ(set.frame, "lab");
  EXPECT_EQ(set.source, "static_trial");
  EXPECT_THAT(set.names(),
              ElementsAre("femoral_head_centre_r", "femoral_head_centre_l", "knee_centre_r",
                          "knee_centre_l", "ankle_centre_r", "ankle_centre_l", "asis_r", "asis_l"));
  // Rounding of sums over 20 frames of numbers ~1e3.
  constexpr double kTol = 1e-9;
  EXPECT_LT((set.find("femoral_head_centre_r")->position_mm - kHipRight).norm(), kTol);
  EXPECT_LT((set.find("femoral_head_centre_l")->position_mm - kHipLeft).norm(), kTol);
  EXPECT_LT((set.find("knee_centre_r")->position_mm - Eigen::Vector3d(10, 500, 90)).norm(), kTol);
  EXPECT_LT((set.find("knee_centre_l")->position_mm - Eigen::Vector3d(10, 500, -90)).norm(), kTol);
  EXPECT_LT((set.find("ankle_centre_r")->position_mm - Eigen::Vector3d(-10, 80, 70)).norm(), kTol);
  EXPECT_LT((set.find("ankle_centre_l")->position_mm - Eigen::Vector3d(-10, 80, -70)).norm(), kTol);
  EXPECT_NEAR(result.pelvis_width_mm, 250.0, kTol);
  EXPECT_NEAR(result.pelvis_depth_mm, 160.0, kTol);
  ASSERT_EQ(result.info.size(), set.landmarks.size());
  for (const StaticTrialLandmarkInfo& info : result.info) {
    EXPECT_EQ(info.frames_used, 20);
    EXPECT_LT(info.spread_mm, kTol);  // identical frames
  }
}

TEST(StaticTrialTest, UnitsGapsAndPsisMarkers) {
  // Centimetres, the sacral marker replaced by two PSIS markers whose
  // midpoint is the old sacral point, gaps in one knee marker.
  auto markers = symmetric_markers();
  markers[2] = {"R.PSIS", {-60, 1000, 40}};
  markers.emplace_back("L.PSIS", Eigen::Vector3d(-60, 1000, -40));
  for (auto& [name, position] : markers) position /= 10.0;
  opensim::MarkerTrajectories trial = make_trial(markers, 30, "cm", 10.0);
  // R.Knee.Lat (marker 3) missing in frames 0-11, and jittering +-1 mm in the rest.
  trial.positions.block(0, 9, 12, 3).setConstant(kNaN);
  for (int f = 12; f < 30; ++f) trial.positions(f, 9) += (f % 2 == 0 ? 0.1 : -0.1);
  StaticTrialOptions options;
  options.markers.posterior = {"R.PSIS", "L.PSIS"};
  options.legs = "right";
  const StaticTrialResult result = landmarks_from_static_trial(trial, options);
  const LandmarkSet& set = result.landmarks;
  EXPECT_THAT(set.names(), ElementsAre("femoral_head_centre_r", "knee_centre_r", "ankle_centre_r",
                                       "asis_r", "asis_l"));
  // cm -> mm: rounding of the divisions above, ~1e-13 mm.
  EXPECT_LT((set.find("femoral_head_centre_r")->position_mm - kHipRight).norm(), 1e-9);
  // The jitter averages out (9 frames each way).
  EXPECT_LT((set.find("knee_centre_r")->position_mm - Eigen::Vector3d(10, 500, 90)).norm(), 1e-9);
  EXPECT_EQ(result.info[1].frames_used, 18);
  // Half of +-1 mm on the x of one of the two markers: 0.5 mm.
  EXPECT_NEAR(result.info[1].spread_mm, 0.5, 1e-9);
  EXPECT_EQ(result.info[0].frames_used, 30);

  options.min_valid_frames = 20;
  const auto message = [&] {
    try {
      landmarks_from_static_trial(trial, options);
    } catch (const InvalidInputError& error) {
      return std::string(error.what());
    }
    return std::string();
  }();
  EXPECT_THAT(message, AllOf(HasSubstr("static.trc: landmark 'knee_centre_r' has all its markers "
                                       "in 18 of 30 frames, fewer than 20"),
                             HasSubstr("hint:")));
}

TEST(StaticTrialTest, UnknownMarkerSuggestsTheClosest) {
  StaticTrialOptions options;
  options.markers.knee_medial_r = "R.Knee.Mid";
  try {
    landmarks_from_static_trial(make_trial(symmetric_markers(), 20), options);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& error) {
    EXPECT_THAT(error.what(), AllOf(HasSubstr("static.trc: marker 'R.Knee.Mid' is not in the "
                                              "trial; did you mean 'R.Knee.Med'?"),
                                    HasSubstr("hint:")));
  }
  options = {};
  options.legs = "middle";
  EXPECT_THROW(landmarks_from_static_trial(make_trial(symmetric_markers(), 20), options),
               InvalidInputError);
}

// Femur length of an OpenSim model: hip joint centre (the femur's origin in
// gait2392) to the knee joint centre at full extension, the knee_r
// translation functions evaluated at knee_angle_r = 0 (mm).
double femur_length_mm(const opensim::OsimModel& model) {
  const opensim::Joint* knee = model.find_joint("knee_r");
  const opensim::Joint* hip = model.find_joint("hip_r");
  EXPECT_NE(knee, nullptr);
  EXPECT_NE(hip, nullptr);
  if (knee == nullptr || hip == nullptr) return 0;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (const opensim::TransformAxis& axis : knee->spatial_transform) {
    if (axis.name.starts_with("translation")) shift += axis.axis * axis.function.evaluate(0.0);
  }
  const Eigen::Vector3d knee_in_femur = knee->parent.to_body(shift);
  const Eigen::Vector3d hip_in_femur = hip->child.to_body(Eigen::Vector3d::Zero());
  return 1000.0 * (knee_in_femur - hip_in_femur).norm();
}

TEST(StaticTrialTest, Subject01StaticTrialGivesAPlausibleFemur) {
  const auto pipelines = test::data_dir() / "gait2392" / "Pipelines";
  const opensim::MarkerTrajectories trial = opensim::read_trc(pipelines / "subject01_static.trc");
  const StaticTrialResult result = landmarks_from_static_trial(trial);
  const LandmarkSet& set = result.landmarks;
  for (const StaticTrialLandmarkInfo& info : result.info) {
    SCOPED_TRACE(info.name);
    EXPECT_EQ(info.frames_used, trial.num_frames());
    // A person standing still: markers wander by a few mm at most.
    EXPECT_LT(info.spread_mm, 5.0);
  }
  const double thigh_r =
      (set.find("femoral_head_centre_r")->position_mm - set.find("knee_centre_r")->position_mm)
          .norm();
  const double thigh_l =
      (set.find("femoral_head_centre_l")->position_mm - set.find("knee_centre_l")->position_mm)
          .norm();
  const double femur =
      femur_length_mm(opensim::read_osim(pipelines / "reference" / "subject01_simbody.osim"));
  RecordProperty("thigh_r_mm", std::to_string(thigh_r));
  RecordProperty("thigh_l_mm", std::to_string(thigh_l));
  RecordProperty("femur_scaled_model_mm", std::to_string(femur));
  RecordProperty("pelvis_width_mm", std::to_string(result.pelvis_width_mm));
  RecordProperty("pelvis_depth_mm", std::to_string(result.pelvis_depth_mm));
  // The subject is 1.80 m tall: 0.245 H = 442 mm (Winter's thigh fraction).
  EXPECT_GT(thigh_r, 380.0);
  EXPECT_LT(thigh_r, 500.0);
  // OpenSim's scaling of this subject (from the same static trial, by
  // marker distances) gives a femur of 454 mm; both legs agree with it within
  // 3 mm. 15 mm allows for what separates the two estimates: skin markers
  // sit ~10 mm off the epicondyles, and the Harrington regression predicts
  // hip centres to about a centimetre.
  EXPECT_NEAR(thigh_r, femur, 15.0);
  EXPECT_NEAR(thigh_l, femur, 15.0);
}

}  // namespace
}  // namespace mmm::landmarks

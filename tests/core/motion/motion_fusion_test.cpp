#include "core/motion/motion_fusion.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "core/errors.h"
#include "core/fit/rigid_fit.h"
#include "core/motion/marker_placement.h"
#include "core/motion/motion_tables.h"
#include "core/motion/retarget.h"
#include "core/opensim/mot.h"
#include "core/opensim/trc.h"
#include "tests/support/motion_fixtures.h"
#include "tests/support/test_data.h"

namespace mmm::motion {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

// Every free coordinate's worst error against the truth (deg, or mm).
double worst_error(const Skeleton& skeleton, const Eigen::MatrixXd& truth, const FusedMotion& fused,
                   bool lengths) {
  double worst = 0;
  for (int c = 0; c < skeleton.num_coordinates(); ++c) {
    const bool length =
        skeleton.coordinates[static_cast<std::size_t>(c)].unit == CoordinateUnit::kLength;
    if (length != lengths) continue;
    const double unit = length ? 1.0 : kDeg;
    worst = std::max(worst, unit * (fused.coordinates.col(c) - truth.col(c)).cwiseAbs().maxCoeff());
  }
  return worst;
}

// All of the model's markers at weight 1: the synthetic trial's own mapping.
MarkerMapping all_markers(const Skeleton& skeleton) {
  MarkerMapping mapping;
  mapping.source = "all_markers.yaml";
  for (const SkeletonMarker& marker : skeleton.markers) {
    mapping.markers.push_back({marker.name, marker.name, 1.0});
  }
  return mapping;
}

TEST(MotionFusionTest, KabschRecoversAKnownRigidTransformOfAMarkerCluster) {
  // A thigh-like cluster of 4 markers moved by a known rotation and
  // translation: Kabsch (the free-body step) gives it back exactly.
  Eigen::MatrixX3d local(4, 3);
  local << 60, -20, 150, 80, 30, 60, 40, 70, -40, 70, -50, -120;
  Eigen::Isometry3d known = Eigen::Isometry3d::Identity();
  known.linear() = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, -1).normalized()).matrix();
  known.translation() = Eigen::Vector3d(510, 880, -95);
  Eigen::MatrixX3d measured(4, 3);
  for (int i = 0; i < 4; ++i) measured.row(i) = (known * local.row(i).transpose()).transpose();
  const fit::RigidFitResult fit =
      fit::rigid_fit(local, measured, Eigen::VectorXd::Constant(4, 2.0));
  EXPECT_LT((fit.rigid.linear() - known.linear()).norm(), 1e-12);
  EXPECT_LT((fit.rigid.translation() - known.translation()).norm(), 1e-9);  // mm
  EXPECT_LT(fit.rms, 1e-9);
}

TEST(MotionFusionTest, RecoversKnownAnglesOfASyntheticWalkToATenthOfADegree) {
  const Skeleton& skeleton = test::subject01_skeleton();
  const Eigen::MatrixXd truth = test::synthetic_coordinates(skeleton, 60);
  const opensim::MarkerTrajectories trial = test::synthetic_trial(skeleton, truth);
  MotionFusionOptions options;
  options.filter.mode = FilterMode::kNone;
  const FusedMotion fused = fuse_motion(skeleton, trial, all_markers(skeleton), options);
  ASSERT_EQ(fused.num_frames(), 60);
  // Noise-free markers: the minimum is the truth. The issue's bar is 0.1
  // degree; the fit reaches ~1e-6 (its convergence tolerance).
  EXPECT_LT(worst_error(skeleton, truth, fused, false), 1e-3);
  EXPECT_LT(worst_error(skeleton, truth, fused, true), 1e-3);
  EXPECT_LT(fused.overall_rms_mm(), 1e-3);
  // The smoother trusts markers to sigma_m = 5 mm and expects constant
  // velocity: on a 1 Hz, 20-degree sinusoid it lags the curvature by about
  // a tenth of a degree at the peaks, no more.
  options.filter.mode = FilterMode::kSmoother;
  const FusedMotion smoothed = fuse_motion(skeleton, trial, all_markers(skeleton), options);
  EXPECT_LT(worst_error(skeleton, truth, smoothed, false), 0.25);
  EXPECT_LT(worst_error(skeleton, truth, smoothed, true), 0.25);
}

TEST(MotionFusionTest, GapsAndNanFramesLowerTheWeightInsteadOfFailing) {
  const Skeleton& skeleton = test::subject01_skeleton();
  const Eigen::MatrixXd truth = test::synthetic_coordinates(skeleton, 60);
  opensim::MarkerTrajectories trial = test::synthetic_trial(skeleton, truth);
  const auto column = [&](const char* name) { return 3 * *trial.marker_index(name); };
  // A gap: the whole right shank cluster missing for frames 20-29, and one
  // frame (40) with no marker at all.
  for (const char* name : {"R.Shank.Upper", "R.Shank.Front", "R.Shank.Rear"}) {
    trial.positions.block(20, column(name), 10, 3).setConstant(std::nan(""));
  }
  trial.positions.row(40).setConstant(std::nan(""));
  MotionFusionOptions options;
  options.filter.mode = FilterMode::kSmoother;
  const FusedMotion fused = fuse_motion(skeleton, trial, all_markers(skeleton), options);
  ASSERT_EQ(fused.num_frames(), 60);
  EXPECT_EQ(fused.markers_used(40), 0);
  EXPECT_TRUE(fused.coordinates.allFinite());
  bool noted = false;
  for (const std::string& note : fused.notes)
    noted = noted || note.find("frame 41") != std::string::npos;
  EXPECT_TRUE(noted);
  // The knee stays determined through the gap by the other markers (the
  // knee and ankle markers remain); the empty frame is bridged by the
  // filter: within a degree of the truth (20 degrees at 1 Hz turn < 2
  // degrees per frame, the smoother interpolates between its neighbours).
  const int knee = *skeleton.coordinate_index("knee_angle_r");
  for (int f = 20; f < 30; ++f)
    EXPECT_NEAR(kDeg * fused.coordinates(f, knee), kDeg * truth(f, knee), 0.1);
  EXPECT_NEAR(kDeg * fused.coordinates(40, knee), kDeg * truth(40, knee), 1.0);
}

TEST(MotionFusionTest, TheSmootherRemovesMarkerNoise) {
  const Skeleton& skeleton = test::subject01_skeleton();
  const Eigen::MatrixXd truth = test::synthetic_coordinates(skeleton, 120);
  opensim::MarkerTrajectories trial = test::synthetic_trial(skeleton, truth);
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0.0, 3.0);  // mm, a typical skin-marker jitter
  for (Eigen::Index i = 0; i < trial.positions.size(); ++i) trial.positions(i) += noise(random);
  MotionFusionOptions raw;
  raw.filter.mode = FilterMode::kNone;
  MotionFusionOptions smooth;
  smooth.filter.mode = FilterMode::kSmoother;
  smooth.filter.marker_noise_mm = 3.0;
  const int knee = *skeleton.coordinate_index("knee_angle_r");
  const auto rms = [&](const FusedMotion& fused) {
    return kDeg * std::sqrt((fused.coordinates.col(knee) - truth.col(knee)).squaredNorm() /
                            static_cast<double>(truth.rows()));
  };
  const double before = rms(fuse_motion(skeleton, trial, all_markers(skeleton), raw));
  const double after = rms(fuse_motion(skeleton, trial, all_markers(skeleton), smooth));
  // Default process noise: ~0.39 vs ~0.51 degree RMS on this trial.
  EXPECT_LT(after, 0.85 * before) << "raw " << before << " deg, smoothed " << after << " deg";
}

TEST(MotionFusionTest, UnknownMarkerNamesAreReportedWithHintsAndTheRootNeedsThree) {
  const Skeleton& skeleton = test::subject01_skeleton();
  const opensim::MarkerTrajectories trial =
      test::synthetic_trial(skeleton, test::synthetic_coordinates(skeleton, 5));
  MarkerMapping mapping = all_markers(skeleton);
  mapping.markers.push_back({"R.ASIS", "R.ASIZ", 1.0});  // the model has no R.ASIZ
  mapping.markers.front().model = "R.ASIZ";
  mapping.markers.push_back({"RASIS_typo", "RASIS_typo", 1.0});
  const TrackingSetup setup = bind_tracking(skeleton, mapping, trial.marker_names);
  ASSERT_FALSE(setup.not_on_model.empty());
  EXPECT_NE(setup.not_on_model.front().find("did you mean 'R.ASIS'"), std::string::npos);
  ASSERT_EQ(setup.not_in_trial.size(), 1u);
  EXPECT_NE(setup.not_in_trial.front().find("RASIS_typo"), std::string::npos);

  // Only unknown names on the pelvis: it cannot be placed, and the error
  // names the mapping file and what was skipped.
  MarkerMapping pelvis_unknown;
  pelvis_unknown.source = "my_mapping.yaml";
  for (const SkeletonMarker& marker : skeleton.markers) {
    const bool pelvis = skeleton.bodies[static_cast<std::size_t>(marker.body)].parent < 0;
    pelvis_unknown.markers.push_back({marker.name, pelvis ? marker.name + "_x" : marker.name, 1.0});
  }
  try {
    fuse_motion(skeleton, trial, pelvis_unknown);
    FAIL() << "a pelvis without tracked markers was accepted";
  } catch (const InvalidInputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("my_mapping.yaml"), std::string::npos) << message;
    EXPECT_NE(message.find("R.ASIS_x"), std::string::npos) << message;
  }
}

TEST(MotionFusionTest, ATruncatedTrcIsAnErrorOrMissingMarkersNeverACrash) {
  const Skeleton& skeleton = test::subject01_skeleton();
  const test::ScratchDir dir("truncated_trc");
  const opensim::MarkerTrajectories trial =
      test::synthetic_trial(skeleton, test::synthetic_coordinates(skeleton, 10));
  opensim::write_trc(trial, dir / "full.trc");
  const std::string text = test::read_text(dir / "full.trc");
  // Cut inside the header: the reader names the file.
  const std::string header_cut = text.substr(0, text.find("Frame#") + 10);
  EXPECT_THROW(opensim::parse_trc(header_cut, "cut_header.trc"), IoError);
  // Cut in the middle of the last data row: that frame's later markers are
  // missing, the fusion runs and says so through the missing count.
  const std::string row_cut = text.substr(0, text.size() - text.size() / 40);
  const opensim::MarkerTrajectories cut = opensim::parse_trc(row_cut, "cut_row.trc");
  ASSERT_EQ(cut.num_frames(), 10);
  EXPECT_GT(cut.count_missing(), 0);
  const FusedMotion fused = fuse_motion(skeleton, cut, all_markers(skeleton));
  EXPECT_LT(fused.markers_used(9), fused.markers_used(0));
  EXPECT_TRUE(fused.coordinates.allFinite());
}

TEST(MotionFusionTest, TimeRangeOutsideTheTrialIsNamed) {
  const Skeleton& skeleton = test::subject01_skeleton();
  const opensim::MarkerTrajectories trial =
      test::synthetic_trial(skeleton, test::synthetic_coordinates(skeleton, 10));
  MotionFusionOptions options;
  options.start_time = 5.0;
  EXPECT_THROW(fuse_motion(skeleton, trial, all_markers(skeleton), options), InvalidInputError);
}

TEST(MotionFusionTest, MarkerPlacementPutsMarkersWhereTheyWereMeasured) {
  const Skeleton& truth_skeleton = test::subject01_skeleton();
  const Eigen::MatrixXd standing = test::synthetic_coordinates(truth_skeleton, 1).replicate(20, 1);
  const opensim::MarkerTrajectories static_trial = test::synthetic_trial(truth_skeleton, standing);
  // The model's thigh markers are 15 mm off where the subject wore them.
  Skeleton model = truth_skeleton;
  for (SkeletonMarker& marker : model.markers) {
    if (marker.name.starts_with("R.Thigh")) marker.local += Eigen::Vector3d(15, -10, 5);
  }
  const MarkerPlacement placed = place_markers(model, static_trial, all_markers(model));
  EXPECT_EQ(placed.frames_averaged, 20);
  EXPECT_GT(placed.rms_before_mm, 1.0);
  // Every non-fixed marker now sits on its measurement at the standing pose.
  EXPECT_LT(placed.rms_after_mm, 1e-6);
  // Walking: the placed model tracks the subject better than the displaced
  // one (the standing pose absorbs part of the offset, so not exactly).
  const Eigen::MatrixXd truth = test::synthetic_coordinates(truth_skeleton, 30);
  const opensim::MarkerTrajectories walk = test::synthetic_trial(truth_skeleton, truth);
  const double displaced = fuse_motion(model, walk, all_markers(model)).overall_rms_mm();
  const double after = fuse_motion(placed.skeleton, walk, all_markers(model)).overall_rms_mm();
  EXPECT_LT(after, 0.5 * displaced) << displaced << " mm vs " << after << " mm";
}

TEST(MotionFusionTest, RetargetingOntoTheSameModelChangesNothingAndScalesTranslations) {
  const Skeleton& skeleton = test::subject01_skeleton();
  const Eigen::MatrixXd truth = test::synthetic_coordinates(skeleton, 20);
  const opensim::MarkerTrajectories trial = test::synthetic_trial(skeleton, truth);
  const FusedMotion fused = fuse_motion(skeleton, trial, all_markers(skeleton));
  const Retargeted same = retarget_motion(fused, skeleton, skeleton, trial, all_markers(skeleton));
  EXPECT_NEAR(same.leg_length_ratio, 1.0, 1e-12);
  EXPECT_NEAR(same.vertical_shift_mm, 0.0, 1e-9);
  EXPECT_LT((same.motion.coordinates - fused.coordinates).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(same.motion.overall_rms_mm(), 0.05);

  // A patient 10 % bigger everywhere: angles copied, stride x 1.1, and the
  // feet on the same ground.
  Skeleton bigger = skeleton;
  for (SkeletonBody& body : bigger.bodies) {
    body.parent_offset.translation() *= 1.1;
    body.child_offset.translation() *= 1.1;
    for (SkeletonAxis& axis : body.axes) {
      if (!axis.rotation) axis.out_scale *= 1.1;
    }
  }
  for (SkeletonMarker& marker : bigger.markers) marker.local *= 1.1;
  const Retargeted big = retarget_motion(fused, skeleton, bigger, trial, all_markers(skeleton));
  EXPECT_NEAR(big.leg_length_ratio, 1.1, 1e-9);
  const int hip = *skeleton.coordinate_index("hip_flexion_r");
  const int tx = *skeleton.coordinate_index("pelvis_tx");
  EXPECT_LT((big.motion.coordinates.col(hip) - fused.coordinates.col(hip)).cwiseAbs().maxCoeff(),
            1e-12);
  // Horizontal travel scales from where the subject started.
  const double start = fused.coordinates(0, tx);
  EXPECT_LT((big.motion.coordinates.col(tx).array() -
             (start + 1.1 * (fused.coordinates.col(tx).array() - start)))
                .abs()
                .maxCoeff(),
            1e-9);
  EXPECT_NEAR(big.target_foot_min_mm, big.source_foot_min_mm, 1e-9);
  EXPECT_LT(same.aligned_marker_rms_mm, 0.05);
}

TEST(MotionFusionTest, MotTableRoundTripsAndComparesToItselfAsZero) {
  const Skeleton& skeleton = test::subject01_skeleton();
  const opensim::MarkerTrajectories trial =
      test::synthetic_trial(skeleton, test::synthetic_coordinates(skeleton, 15));
  const FusedMotion fused = fuse_motion(skeleton, trial, all_markers(skeleton));
  const test::ScratchDir dir("motion_mot");
  opensim::write_mot(coordinate_table(fused, "synthetic_ik"), dir / "angles.mot");
  const opensim::StorageTable back = opensim::read_mot(dir / "angles.mot");
  EXPECT_TRUE(back.in_degrees);
  const std::vector<CoordinateDifference> differences = compare_coordinates(fused, back);
  ASSERT_EQ(static_cast<int>(differences.size()), skeleton.num_coordinates());
  for (const CoordinateDifference& d : differences) {
    EXPECT_EQ(d.samples, 15);
    EXPECT_LT(d.rms, 1e-9) << d.coordinate;
  }
  // Degrees and metres, as OpenSim writes them.
  const int knee = *skeleton.coordinate_index("knee_angle_r");
  const int tx = *skeleton.coordinate_index("pelvis_tx");
  EXPECT_NEAR(back.values(3, knee), kDeg * fused.coordinates(3, knee), 1e-9);
  EXPECT_NEAR(back.values(3, tx), fused.coordinates(3, tx) / 1000.0, 1e-12);
}

}  // namespace
}  // namespace mmm::motion

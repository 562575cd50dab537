#include "core/opensim/trc.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <charconv>
#include <cmath>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "core/opensim/marker_set.h"
#include "tests/support/test_data.h"
#include "tests/support/test_helpers.h"

namespace mmm::opensim {
namespace {

using ::testing::HasSubstr;

using test::io_error_of;
using test::kNaN;

std::string fixed(double value, int decimals) {
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                    std::chars_format::fixed, decimals);
  return {buffer.data(), result.ptr};
}

// Header lines 1-5 and the blank line 6 of a tab-separated .trc; data rows
// start on line 7.
std::string header(const std::vector<std::string>& names, int num_frames,
                   std::string_view units = "mm", double rate = 100.0) {
  std::string text = "PathFileType\t4\t(X/Y/Z)\ttest.trc\n";
  text +=
      "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame"
      "\tOrigNumFrames\n";
  text += fixed(rate, 2) + "\t" + fixed(rate, 2) + "\t" + std::to_string(num_frames) + "\t" +
          std::to_string(names.size()) + "\t" + std::string(units) + "\t" + fixed(rate, 2) +
          "\t1\t" + std::to_string(num_frames) + "\n";
  text += "Frame#\tTime";
  for (const std::string& name : names) text += "\t" + name + "\t\t";
  text += "\n\t";
  for (std::size_t m = 1; m <= names.size(); ++m) {
    const std::string i = std::to_string(m);
    for (const char axis : {'X', 'Y', 'Z'}) {
      text += '\t';
      text += axis;
      text += i;
    }
  }
  return text + "\n\n";
}

// Two markers, two frames, all values present: the base of the malformed cases.
std::string two_frames() {
  return header({"A", "B"}, 2) +
         "1\t0.00\t1.0\t2.0\t3.0\t4.0\t5.0\t6.0\n"
         "2\t0.01\t1.5\t2.5\t3.5\t4.5\t5.5\t6.5\n";
}

// --- Analytic cases -------------------------------------------------------

TEST(TrcTest, MarkerOnAKnownLineIsReadBack) {
  // Marker "Moving" runs along p(t) = p0 + v t (m); "Still" stays at q.
  const Eigen::Vector3d p0(0.25, 1.0, -0.5);
  const Eigen::Vector3d v(1.2, -0.3, 0.05);
  const Eigen::Vector3d q(0.1, 0.2, 0.3);
  constexpr int kFrames = 11;
  constexpr double kRate = 100.0;
  std::string text = header({"Moving", "Still"}, kFrames, "m", kRate);
  for (int f = 0; f < kFrames; ++f) {
    const double t = f / kRate;
    const Eigen::Vector3d p = p0 + v * t;
    text += std::to_string(f + 1) + "\t" + fixed(t, 6);
    for (int a = 0; a < 3; ++a) text += "\t" + fixed(p(a), 6);
    for (int a = 0; a < 3; ++a) text += "\t" + fixed(q(a), 6);
    text += "\n";
  }
  const MarkerTrajectories trc = parse_trc(text, "line.trc");

  EXPECT_TRUE(trc.warnings.empty());
  EXPECT_EQ(trc.source, "line.trc");
  EXPECT_EQ(trc.num_frames(), kFrames);
  EXPECT_EQ(trc.num_markers(), 2);
  EXPECT_EQ(trc.units, "m");
  EXPECT_EQ(trc.unit_to_mm, 1000.0);
  EXPECT_EQ(trc.data_rate, kRate);
  EXPECT_EQ(trc.camera_rate, kRate);
  ASSERT_EQ(trc.marker_index("Moving"), 0);
  ASSERT_EQ(trc.marker_index("Still"), 1);
  EXPECT_FALSE(trc.marker_index("moving").has_value());  // names are case-sensitive
  EXPECT_EQ(trc.count_missing(), 0);
  // Six printed decimals: the text is within half a unit of the 6th decimal.
  constexpr double kPrinted = 0.5e-6;
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_EQ(trc.frame_numbers[static_cast<std::size_t>(f)], f + 1);
    EXPECT_NEAR(trc.times(f), f / kRate, kPrinted);
    const Eigen::Vector3d expected = p0 + v * (f / kRate);
    EXPECT_LE((trc.position(f, 0) - expected).cwiseAbs().maxCoeff(), kPrinted) << "frame " << f;
    EXPECT_LE((trc.position(f, 1) - q).cwiseAbs().maxCoeff(), kPrinted) << "frame " << f;
  }
  // The velocity from the end points: two printing roundings (kPrinted each)
  // over 0.1 s, plus 1e-12 for the arithmetic on numbers of order 1.
  const Eigen::Vector3d velocity =
      (trc.position(kFrames - 1, 0) - trc.position(0, 0)) / (trc.times(kFrames - 1) - trc.times(0));
  EXPECT_LE((velocity - v).cwiseAbs().maxCoeff(), 2 * kPrinted / 0.1 + 1e-12);
  // middleCols(3m, 3) is the #frames by 3 trajectory of marker m.
  EXPECT_EQ(trc.positions.middleCols(3, 3).rows(), kFrames);
}

TEST(TrcTest, FrameAtTimeFindsTheNearestFrame) {
  const MarkerTrajectories trc = parse_trc(two_frames(), "two.trc");
  EXPECT_EQ(trc.frame_at_time(0.0), 0);
  EXPECT_EQ(trc.frame_at_time(0.004), 0);
  EXPECT_EQ(trc.frame_at_time(0.006), 1);
  EXPECT_EQ(trc.frame_at_time(0.01), 1);
  // Half a frame period (0.005 s at 100 Hz) beyond either end still maps.
  EXPECT_EQ(trc.frame_at_time(-0.004), 0);
  EXPECT_EQ(trc.frame_at_time(0.014), 1);
  EXPECT_FALSE(trc.frame_at_time(-0.006).has_value());
  EXPECT_FALSE(trc.frame_at_time(0.016).has_value());
  EXPECT_FALSE(trc.frame_at_time(kNaN).has_value());
  EXPECT_THROW((void)trc.position(2, 0), InvalidInputError);
  EXPECT_THROW((void)trc.position(0, 2), InvalidInputError);
  EXPECT_THROW((void)trc.position(-1, 0), InvalidInputError);
}

TEST(TrcTest, MissingValuesAreNaN) {
  // Frame 1: B's Y empty (B missing as a whole). Frame 2: A written as NaN.
  // Frame 3: the row stops after A (B missing, the row is short).
  const std::string text = header({"A", "B"}, 3) +
                           "1\t0.00\t1\t2\t3\t4\t\t6\n"
                           "2\t0.01\tNaN\tNaN\tNaN\t4\t5\t6\n"
                           "3\t0.02\t1\t2\t3\n";
  const MarkerTrajectories trc = parse_trc(text, "gaps.trc");
  EXPECT_EQ(trc.position(0, 0), Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(trc.position(0, 1).array().isNaN().all());
  EXPECT_TRUE(trc.position(1, 0).array().isNaN().all());
  EXPECT_EQ(trc.position(1, 1), Eigen::Vector3d(4, 5, 6));
  EXPECT_TRUE(trc.position(2, 1).array().isNaN().all());
  EXPECT_EQ(trc.count_missing(), 3);
  ASSERT_EQ(trc.warnings.size(), 1U);
  EXPECT_THAT(trc.warnings[0], HasSubstr("shorter than the header"));
}

TEST(TrcTest, ToleratesSpacesCrlfTrailingColumnsAndAWrongFrameCount) {
  // Space-separated, CRLF line ends, NumFrames 5 for 2 rows, trailing tabs.
  const std::string text =
      "PathFileType 4 (X/Y/Z) spaced.trc\r\n"
      "DataRate CameraRate NumFrames NumMarkers Units\r\n"
      "  120   120   5   1   cm\r\n"
      "Frame#  Time  Heel\r\n"
      "   X1 Y1 Z1\r\n"
      "\r\n"
      "10   0.000   1.5  -2.5  3.25\r\n"
      "11\t0.008333\t1.5\t-2.5\t3.5\t\t\t\r\n"
      "\r\n";
  const MarkerTrajectories trc = parse_trc(text, "spaced.trc");
  EXPECT_EQ(trc.num_frames(), 2);
  EXPECT_EQ(trc.num_markers(), 1);
  EXPECT_EQ(trc.unit_to_mm, 10.0);
  EXPECT_EQ(trc.camera_rate, 120.0);
  EXPECT_EQ(trc.orig_data_rate, 120.0);  // absent: DataRate
  EXPECT_EQ(trc.orig_num_frames, 2);     // absent: the data's frame count
  EXPECT_EQ(trc.frame_numbers, (std::vector<int>{10, 11}));
  EXPECT_EQ(trc.position(1, 0), Eigen::Vector3d(1.5, -2.5, 3.5));
  ASSERT_EQ(trc.warnings.size(), 1U);
  EXPECT_THAT(trc.warnings[0], HasSubstr("NumFrames says 5"));
}

TEST(TrcTest, WriteThenReadIsExact) {
  MarkerTrajectories original;
  original.data_rate = 60.0;
  original.camera_rate = 120.0;
  original.orig_data_rate = 60.0;
  original.orig_data_start_frame = 7;
  original.orig_num_frames = 400;
  original.units = "mm";
  original.marker_names = {"R.ASIS", "L.ASIS", "V Sacral"};  // a space is fine with tabs
  constexpr int kFrames = 25;
  original.times.resize(kFrames);
  original.positions.resize(kFrames, 9);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-2000.0, 2000.0);
  for (int f = 0; f < kFrames; ++f) {
    original.frame_numbers.push_back(f + 7);
    original.times(f) = (f + 6) / 60.0;
    for (int c = 0; c < 9; ++c) original.positions(f, c) = coordinate(random);
  }
  original.positions.block(3, 3, 4, 3).setConstant(kNaN);  // L.ASIS lost for 4 frames

  test::ScratchDir scratch("trc");
  write_trc(original, scratch / "round.trc");
  const MarkerTrajectories back = read_trc(scratch / "round.trc");

  // Shortest round-trip text: every double reads back bit for bit (tolerance 0).
  EXPECT_TRUE(back.warnings.empty());
  EXPECT_EQ(back.marker_names, original.marker_names);
  EXPECT_EQ(back.frame_numbers, original.frame_numbers);
  EXPECT_EQ(back.data_rate, original.data_rate);
  EXPECT_EQ(back.camera_rate, original.camera_rate);
  EXPECT_EQ(back.orig_data_start_frame, 7);
  EXPECT_EQ(back.orig_num_frames, 400);
  EXPECT_EQ(back.units, "mm");
  ASSERT_EQ(back.times.size(), kFrames);
  EXPECT_EQ(back.times, original.times);
  EXPECT_EQ(back.count_missing(), 4);
  ASSERT_EQ(back.positions.rows(), kFrames);
  ASSERT_EQ(back.positions.cols(), 9);
  for (int f = 0; f < kFrames; ++f) {
    for (int c = 0; c < 9; ++c) {
      const double a = original.positions(f, c);
      const double b = back.positions(f, c);
      EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << f << ", " << c;
    }
  }

  // With 3 decimals the values come back within half a unit of the 3rd decimal.
  write_trc(original, scratch / "rounded.trc", {.decimals = 3});
  const MarkerTrajectories rounded = read_trc(scratch / "rounded.trc");
  ASSERT_EQ(rounded.positions.rows(), kFrames);
  ASSERT_EQ(rounded.positions.cols(), 9);
  constexpr double kHalfUnit = 0.5e-3 * (1 + 1e-9);  // + the representation error of the text
  EXPECT_LE((rounded.times - original.times).cwiseAbs().maxCoeff(), kHalfUnit);
  const Eigen::ArrayXXd difference = (rounded.positions - original.positions).array();
  EXPECT_LE(difference.isNaN().select(0.0, difference.abs()).maxCoeff(), kHalfUnit);
}

TEST(TrcTest, WriteRejectsInconsistentData) {
  MarkerTrajectories bad = parse_trc(two_frames(), "two.trc");
  test::ScratchDir scratch("trc-bad");
  MarkerTrajectories duplicate = bad;
  duplicate.marker_names[1] = "A";
  EXPECT_THROW(write_trc(duplicate, scratch / "x.trc"), InvalidInputError);
  MarkerTrajectories wrong_width = bad;
  wrong_width.positions.conservativeResize(2, 5);
  EXPECT_THROW(write_trc(wrong_width, scratch / "x.trc"), InvalidInputError);
  MarkerTrajectories backwards = bad;
  backwards.times(1) = -1.0;
  EXPECT_THROW(write_trc(backwards, scratch / "x.trc"), InvalidInputError);
  MarkerTrajectories inches = bad;
  inches.units = "in";
  EXPECT_THROW(write_trc(inches, scratch / "x.trc"), InvalidInputError);
  EXPECT_THROW(write_trc(bad, scratch / "no_such_folder" / "x.trc"), IoError);
}

// --- Malformed input: each error names the line (and column) ---------------

TEST(TrcTest, RejectsAFileThatIsNotATrc) {
  const std::string message = io_error_of([] { (void)parse_trc("time\tknee\n0\t1\n", "not.trc"); });
  EXPECT_THAT(message, HasSubstr("not.trc: line 1"));
  EXPECT_THAT(message, HasSubstr("expected 'PathFileType'"));
  EXPECT_THAT(io_error_of([] { (void)parse_trc("", "empty.trc"); }), HasSubstr("empty"));
}

TEST(TrcTest, RejectsANonNumericFieldNamingLineAndColumn) {
  std::string text = two_frames();
  text.replace(text.find("5.5"), 3, "5,5");
  const std::string message = io_error_of([&] { (void)parse_trc(text, "comma.trc"); });
  EXPECT_THAT(message, HasSubstr("line 8, column 'Y2' (marker 'B')"));
  EXPECT_THAT(message, HasSubstr("got '5,5'"));
  std::string bad_frame = two_frames();
  bad_frame.replace(bad_frame.find("\n2\t"), 3, "\nx2\t");
  EXPECT_THAT(io_error_of([&] { (void)parse_trc(bad_frame, "f.trc"); }),
              HasSubstr("line 8, column 'Frame#'"));
}

TEST(TrcTest, RejectsNumMarkersThatDisagreesWithTheNames) {
  std::string text = two_frames();
  text.replace(text.find("\t2\tmm"), 5, "\t3\tmm");
  const std::string message = io_error_of([&] { (void)parse_trc(text, "count.trc"); });
  EXPECT_THAT(message, HasSubstr("line 4"));
  EXPECT_THAT(message, HasSubstr("NumMarkers 3 but this line names 2"));
}

TEST(TrcTest, RejectsDuplicateMarkerNames) {
  const std::string text = header({"A", "A"}, 1) + "1\t0\t1\t2\t3\t4\t5\t6\n";
  const std::string message = io_error_of([&] { (void)parse_trc(text, "dup.trc"); });
  EXPECT_THAT(message, HasSubstr("line 4, column 'A': duplicate marker name"));
}

TEST(TrcTest, RejectsTimesThatDoNotIncrease) {
  std::string text = two_frames();
  text.replace(text.find("0.01"), 4, "0.00");
  const std::string message = io_error_of([&] { (void)parse_trc(text, "time.trc"); });
  EXPECT_THAT(message, HasSubstr("line 8, column 'Time'"));
  EXPECT_THAT(message, HasSubstr("does not increase"));
}

TEST(TrcTest, RejectsANaNTime) {
  std::string text = two_frames();
  text.replace(text.find("0.01"), 4, "nan");
  EXPECT_THAT(io_error_of([&] { (void)parse_trc(text, "nan.trc"); }),
              HasSubstr("line 8, column 'Time': expected a finite time"));
}

TEST(TrcTest, RejectsUnknownUnits) {
  std::string text = two_frames();
  text.replace(text.find("\tmm\t"), 4, "\tin\t");
  EXPECT_THAT(io_error_of([&] { (void)parse_trc(text, "inch.trc"); }),
              HasSubstr("line 3, column 'Units': unknown length unit 'in', expected mm, cm or m"));
}

TEST(TrcTest, RejectsARowLongerThanTheHeader) {
  const std::string text = two_frames() + "3\t0.02\t1\t2\t3\t4\t5\t6\t7\n";
  const std::string message = io_error_of([&] { (void)parse_trc(text, "long.trc"); });
  EXPECT_THAT(message, HasSubstr("line 9: the row has 9 values but the header has 8 columns"));
}

TEST(TrcTest, RejectsBrokenHeaderLines) {
  // Coordinate labels for one marker only.
  std::string labels = two_frames();
  labels.replace(labels.find("\tX2\tY2\tZ2"), 9, "");
  EXPECT_THAT(io_error_of([&] { (void)parse_trc(labels, "labels.trc"); }),
              HasSubstr("line 5: expected 3 coordinate labels"));
  // A value missing on line 3.
  std::string values = two_frames();
  values.replace(values.find("\t1\t2\n"), 5, "\t2\n");
  EXPECT_THAT(io_error_of([&] { (void)parse_trc(values, "values.trc"); }),
              HasSubstr("line 3: the header has 8 keys on line 2 but 7 values"));
  // No data at all.
  EXPECT_THAT(io_error_of([] { (void)parse_trc(header({"A"}, 0), "nodata.trc"); }),
              HasSubstr("no data rows"));
  // Truncated header.
  EXPECT_THAT(io_error_of([] { (void)parse_trc("PathFileType\t4\n", "short.trc"); }),
              HasSubstr("ends before header line 2"));
}

TEST(TrcTest, RejectsAMissingFile) {
  const std::string message =
      io_error_of([] { (void)read_trc(test::gait2392_pipelines() / "no_such_trial.trc"); });
  EXPECT_THAT(message, HasSubstr("no_such_trial.trc: no such file"));
}

// --- Real data -------------------------------------------------------------

TEST(TrcTest, ReadsTheWalkingTrial) {
  const MarkerTrajectories walk = read_trc(test::gait2392_pipelines() / "subject01_walk1.trc");
  EXPECT_TRUE(walk.warnings.empty());
  EXPECT_EQ(walk.num_frames(), 151);
  EXPECT_EQ(walk.num_markers(), 41);
  EXPECT_EQ(walk.units, "mm");
  EXPECT_EQ(walk.unit_to_mm, 1.0);
  EXPECT_EQ(walk.data_rate, 60.0);
  EXPECT_EQ(walk.times(0), 0.0);
  EXPECT_EQ(walk.times(150), 2.5);
  EXPECT_EQ(walk.frame_numbers.front(), 1);
  EXPECT_EQ(walk.frame_numbers.back(), 151);
  EXPECT_EQ(walk.marker_names.front(), "R.ASIS");
  EXPECT_EQ(walk.marker_names.back(), "Top.Head");
  // This trial has no gaps: every one of the 151 x 41 samples is present.
  EXPECT_EQ(walk.count_missing(), 0);
  // Frame 1 of R.ASIS as printed in the file (6 decimals, parsed correctly rounded).
  EXPECT_EQ(walk.position(0, 0), Eigen::Vector3d(617.247620, 1055.275020, 170.781980));
  // Frame 61 is at 1.000000 s.
  EXPECT_EQ(walk.frame_at_time(1.0), 60);
  EXPECT_EQ(walk.position(60, 0), Eigen::Vector3d(615.439270, 1079.433110, 176.575780));
  // The lab frame is Y up: the head is above the heels (mm) in every frame.
  const Eigen::Index head = *walk.marker_index("Top.Head");
  const Eigen::Index heel = *walk.marker_index("R.Heel");
  EXPECT_GT((walk.positions.col(3 * head + 1) - walk.positions.col(3 * heel + 1)).minCoeff(),
            1000.0);
}

TEST(TrcTest, ReadsTheStaticTrial) {
  const MarkerTrajectories still = read_trc(test::gait2392_pipelines() / "subject01_static.trc");
  EXPECT_TRUE(still.warnings.empty());
  EXPECT_EQ(still.num_frames(), 300);
  EXPECT_EQ(still.num_markers(), 49);
  EXPECT_EQ(still.units, "mm");
  EXPECT_EQ(still.count_missing(), 0);
  // Times are printed rounded to ms (0.017 for 1/60 s); frame 31 is 0.5 s.
  EXPECT_EQ(still.frame_at_time(0.5), 30);
  EXPECT_TRUE(still.marker_index("R.Knee.Med").has_value());
  EXPECT_TRUE(still.marker_index("L.Ankle.Lat").has_value());
}

TEST(TrcTest, TrialsCarryEveryMarkerTheSetupsUse) {
  const MarkerTrajectories still = read_trc(test::gait2392_pipelines() / "subject01_static.trc");
  for (const MarkerDefinition& marker :
       read_marker_set(test::gait2392_pipelines() / "gait2392_Scale_MarkerSet.xml")) {
    EXPECT_TRUE(still.marker_index(marker.name).has_value()) << marker.name;
  }
  const MarkerTrajectories walk = read_trc(test::gait2392_pipelines() / "subject01_walk1.trc");
  for (const auto& task :
       read_ik_task_weights(test::gait2392_pipelines() / "subject01_Setup_IK.xml")) {
    EXPECT_TRUE(walk.marker_index(task.first).has_value()) << task.first;
  }
}

TEST(TrcTest, WalkingTrialSurvivesARoundTrip) {
  const MarkerTrajectories walk = read_trc(test::gait2392_pipelines() / "subject01_walk1.trc");
  test::ScratchDir scratch("trc-walk");
  write_trc(walk, scratch / "walk.trc");
  const MarkerTrajectories back = read_trc(scratch / "walk.trc");
  EXPECT_EQ(back.marker_names, walk.marker_names);
  EXPECT_EQ(back.frame_numbers, walk.frame_numbers);
  ASSERT_EQ(back.positions.rows(), walk.positions.rows());
  ASSERT_EQ(back.positions.cols(), walk.positions.cols());
  EXPECT_EQ(back.times, walk.times);          // exact: shortest round-trip text
  EXPECT_EQ(back.positions, walk.positions);  // exact, no NaN in this trial
}

}  // namespace
}  // namespace mmm::opensim

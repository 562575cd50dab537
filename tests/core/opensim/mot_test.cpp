#include "core/opensim/mot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "tests/support/test_helpers.h"

namespace mmm::opensim {
namespace {

using ::testing::HasSubstr;

using test::io_error_of;
using test::kNaN;

std::filesystem::path ik_result() {
  return test::data_dir() / "gait2392" / "Pipelines" / "reference" / "subject01_walk1_ik.mot";
}

// OpenSim 4 layout, 3 rows; the labels are on line 7, the rows on 8-10.
const std::string kSmall =
    "Coordinates\n"
    "version=1\n"
    "nRows=3\n"
    "nColumns=3\n"
    "inDegrees=no\n"
    "endheader\n"
    "time\tknee_angle_r\tpelvis_ty\n"
    "0.0\t0.1\t1.0\n"
    "0.1\t0.3\t0.9\n"
    "0.2\t0.2\t0.8\n";

// --- Analytic cases -------------------------------------------------------

TEST(MotTest, ReadsAStorageFileAndInterpolatesLinearly) {
  const StorageTable table = parse_mot(kSmall, "small.sto");
  EXPECT_TRUE(table.warnings.empty());
  EXPECT_EQ(table.name, "Coordinates");
  EXPECT_FALSE(table.in_degrees);
  EXPECT_TRUE(table.in_degrees_stated);
  EXPECT_EQ(table.column_names, (std::vector<std::string>{"knee_angle_r", "pelvis_ty"}));
  ASSERT_EQ(table.num_rows(), 3);
  ASSERT_EQ(table.num_columns(), 2);
  EXPECT_EQ(table.times, Eigen::Vector3d(0.0, 0.1, 0.2));
  EXPECT_EQ(table.column_index("pelvis_ty"), 1);
  EXPECT_FALSE(table.column_index("time").has_value());  // time is not a data column
  EXPECT_EQ(table.column("knee_angle_r"), Eigen::Vector3d(0.1, 0.3, 0.2));
  // At a row's time: exactly that row.
  EXPECT_EQ(table.interpolate(0.1), Eigen::RowVector2d(0.3, 0.9));
  // pelvis_ty is the line 1 - t, knee_angle_r piecewise linear; a few ulps
  // of numbers of order 1 from the weights.
  constexpr double kRoundOff = 1e-14;
  for (const double t : {0.0, 0.025, 0.05, 0.1, 0.13, 0.2}) {
    EXPECT_NEAR(table.value_at("pelvis_ty", t), 1.0 - t, kRoundOff) << t;
    const double knee = t <= 0.1 ? 0.1 + 2.0 * t : 0.3 - (t - 0.1);
    EXPECT_NEAR(table.value_at("knee_angle_r", t), knee, kRoundOff) << t;
  }
  EXPECT_THROW((void)table.interpolate(-0.01), InvalidInputError);
  EXPECT_THROW((void)table.interpolate(0.21), InvalidInputError);
  EXPECT_THROW((void)table.interpolate(kNaN), InvalidInputError);
  EXPECT_THROW((void)table.column("hip_flexion_r"), InvalidInputError);
  EXPECT_THROW((void)table.value_at("hip_flexion_r", 0.1), InvalidInputError);
}

TEST(MotTest, WriteThenReadIsExact) {
  StorageTable original;
  original.name = "ik";
  original.in_degrees = true;
  original.column_names = {"hip_flexion_r", "knee_angle_r", "pelvis_tx"};
  original.times = Eigen::VectorXd::LinSpaced(7, 0.5, 0.6);
  original.values.resize(7, 3);
  for (int r = 0; r < 7; ++r) {
    original.values(r, 0) = 30.0 * std::sin(r / 3.0);
    original.values(r, 1) = -std::numbers::pi * r / 7.0;
    original.values(r, 2) = 1e-9 * r + 0.5;
  }
  original.values(4, 1) = kNaN;

  test::ScratchDir scratch("mot");
  write_mot(original, scratch / "round.mot");
  const std::string text = test::read_text(scratch / "round.mot");
  // The header OpenSim's storage readers expect.
  EXPECT_EQ(text.substr(0, text.find("time")),
            "ik\nversion=1\nnRows=7\nnColumns=4\ninDegrees=yes\nendheader\n");
  EXPECT_THAT(text, HasSubstr("time\thip_flexion_r\tknee_angle_r\tpelvis_tx\n"));

  const StorageTable back = read_mot(scratch / "round.mot");
  EXPECT_TRUE(back.warnings.empty());
  EXPECT_EQ(back.name, "ik");
  EXPECT_TRUE(back.in_degrees);
  EXPECT_EQ(back.column_names, original.column_names);
  ASSERT_EQ(back.times.size(), 7);
  ASSERT_EQ(back.values.rows(), 7);
  ASSERT_EQ(back.values.cols(), 3);
  // Shortest round-trip text: every double reads back bit for bit (tolerance 0).
  EXPECT_EQ(back.times, original.times);
  for (int r = 0; r < 7; ++r) {
    for (int c = 0; c < 3; ++c) {
      const double a = original.values(r, c);
      const double b = back.values(r, c);
      EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << r << ", " << c;
    }
  }

  // With 4 decimals: within half a unit of the 4th decimal.
  write_mot(original, scratch / "rounded.mot", {.decimals = 4});
  const StorageTable rounded = read_mot(scratch / "rounded.mot");
  ASSERT_EQ(rounded.values.rows(), 7);
  ASSERT_EQ(rounded.values.cols(), 3);
  constexpr double kHalfUnit = 0.5e-4 * (1 + 1e-9);  // + the representation error of the text
  const Eigen::ArrayXXd difference = (rounded.values - original.values).array();
  EXPECT_LE(difference.isNaN().select(0.0, difference.abs()).maxCoeff(), kHalfUnit);
  EXPECT_LE((rounded.times - original.times).cwiseAbs().maxCoeff(), kHalfUnit);
}

TEST(MotTest, WriteRejectsInconsistentTables) {
  const StorageTable good = parse_mot(kSmall, "small.sto");
  test::ScratchDir scratch("mot-bad");
  StorageTable blank_name = good;
  blank_name.column_names[0] = "knee angle";
  EXPECT_THROW(write_mot(blank_name, scratch / "x.mot"), InvalidInputError);
  StorageTable narrow = good;
  narrow.values.conservativeResize(3, 1);
  EXPECT_THROW(write_mot(narrow, scratch / "x.mot"), InvalidInputError);
  StorageTable unsorted = good;
  unsorted.times(2) = 0.05;
  EXPECT_THROW(write_mot(unsorted, scratch / "x.mot"), InvalidInputError);
  StorageTable keyed = good;
  keyed.name = "a=b";
  EXPECT_THROW(write_mot(keyed, scratch / "x.mot"), InvalidInputError);
  EXPECT_THROW(write_mot(good, scratch / "no_such_folder" / "x.mot"), IoError);
}

TEST(MotTest, InDegreesIsStatedOrInferred) {
  const std::string bare = "motion\nnRows=1\nnColumns=2\nendheader\ntime a\n0 1\n";
  const StorageTable radians = parse_mot(bare, "bare.sto");
  EXPECT_FALSE(radians.in_degrees);
  EXPECT_FALSE(radians.in_degrees_stated);
  ASSERT_EQ(radians.warnings.size(), 1U);
  EXPECT_THAT(radians.warnings[0], HasSubstr("does not state inDegrees; taken as no"));
  EXPECT_TRUE(parse_mot(bare, "bare.sto", {.in_degrees_if_unstated = true}).in_degrees);
  // A SIMM motion header: degrees.
  const std::string simm =
      "name walk\ndatacolumns 2\ndatarows 2\notherdata 1\nrange 0 1\nendheader\n"
      "time a\n0 10\n1 20\n";
  const StorageTable degrees = parse_mot(simm, "simm.mot");
  EXPECT_EQ(degrees.name, "walk");
  EXPECT_TRUE(degrees.in_degrees);
  EXPECT_FALSE(degrees.in_degrees_stated);
  // CRLF, spaces, blank lines and trailing blanks are fine.
  const StorageTable crlf = parse_mot(
      "x\r\ninDegrees = yes\r\nendheader\r\n\r\ntime   a  \r\n 0  1 \t\r\n\r\n", "crlf.sto");
  EXPECT_TRUE(crlf.in_degrees);
  EXPECT_EQ(crlf.values(0, 0), 1.0);
}

// --- Malformed input: each error names the line (and column) ---------------

TEST(MotTest, RejectsAFileWithoutEndheader) {
  EXPECT_THAT(io_error_of([] { (void)parse_mot("time\ta\n0\t1\n", "plain.mot"); }),
              HasSubstr("no 'endheader' line"));
  EXPECT_THAT(
      io_error_of([] { (void)parse_mot("PathFileType\t4\t(X/Y/Z)\tx.trc\n", "marker.mot"); }),
      HasSubstr("read it with read_trc"));
}

TEST(MotTest, RejectsAFirstLabelOtherThanTime) {
  std::string text = kSmall;
  text.replace(text.find("time\t"), 4, "Frame");
  EXPECT_THAT(io_error_of([&] { (void)parse_mot(text, "label.mot"); }),
              HasSubstr("line 7, column 'Frame': expected 'time' as the first column label"));
}

TEST(MotTest, RejectsAColumnCountThatDisagreesWithTheLabels) {
  std::string text = kSmall;
  text.replace(text.find("nColumns=3"), 10, "nColumns=2");
  const std::string message = io_error_of([&] { (void)parse_mot(text, "count.mot"); });
  EXPECT_THAT(message, HasSubstr("line 4, column 'nColumns'"));
  EXPECT_THAT(message, HasSubstr("announces 2 columns but line 7 has 3 labels"));
}

TEST(MotTest, RejectsARowOfTheWrongLength) {
  std::string text = kSmall;
  text.replace(text.find("0.3\t0.9"), 7, "0.3");
  EXPECT_THAT(io_error_of([&] { (void)parse_mot(text, "short.mot"); }),
              HasSubstr("line 9: the row has 2 values, expected one per column label (3"));
}

TEST(MotTest, RejectsANonNumericFieldNamingLineAndColumn) {
  std::string text = kSmall;
  text.replace(text.find("0.9"), 3, "abc");
  EXPECT_THAT(io_error_of([&] { (void)parse_mot(text, "text.mot"); }),
              HasSubstr("line 9, column 'pelvis_ty': expected a number (or NaN), got 'abc'"));
}

TEST(MotTest, RejectsTimesThatDoNotIncreaseOrAreNaN) {
  std::string repeated = kSmall;
  repeated.replace(repeated.find("0.2\t"), 3, "0.1");
  EXPECT_THAT(io_error_of([&] { (void)parse_mot(repeated, "repeat.mot"); }),
              HasSubstr("line 10, column 'time': time 0.1 s does not increase"));
  std::string nan_time = kSmall;
  nan_time.replace(nan_time.find("0.1\t0.3"), 3, "NaN");
  EXPECT_THAT(io_error_of([&] { (void)parse_mot(nan_time, "nan.mot"); }),
              HasSubstr("line 9, column 'time': expected a finite time"));
}

TEST(MotTest, RejectsBadHeaderValues) {
  std::string flag = kSmall;
  flag.replace(flag.find("inDegrees=no"), 12, "inDegrees=maybe");
  EXPECT_THAT(io_error_of([&] { (void)parse_mot(flag, "flag.mot"); }),
              HasSubstr("line 5, column 'inDegrees': expected yes or no, got 'maybe'"));
  std::string vec3 = kSmall;
  vec3.replace(vec3.find("version=1"), 9, "DataType=Vec3");
  EXPECT_THAT(io_error_of([&] { (void)parse_mot(vec3, "vec3.sto"); }),
              HasSubstr("expected DataType=double"));
  EXPECT_THAT(io_error_of([] { (void)parse_mot("x\nendheader\ntime\ta\n", "empty.sto"); }),
              HasSubstr("no data rows"));
}

TEST(MotTest, RejectsAMissingFile) {
  EXPECT_THAT(io_error_of([] { (void)read_mot(ik_result().parent_path() / "absent.mot"); }),
              HasSubstr("absent.mot: no such file"));
}

// --- Real data -------------------------------------------------------------

TEST(MotTest, ReadsTheReferenceInverseKinematics) {
  const StorageTable ik = read_mot(ik_result());
  EXPECT_EQ(ik.name, "first trial");
  ASSERT_EQ(ik.num_rows(), 211);
  // 164 data columns: 23 coordinates, 41 markers x 3, 2 force plates x 9.
  ASSERT_EQ(ik.num_columns(), 164);
  EXPECT_EQ(ik.times(0), 0.5);
  EXPECT_EQ(ik.times(210), 4.0);
  EXPECT_EQ(ik.column_names.front(), "pelvis_tx");
  for (const char* coordinate :
       {"pelvis_tilt", "hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r",
        "ankle_angle_r", "subtalar_angle_r", "mtp_angle_r", "knee_angle_l", "lumbar_extension"}) {
    EXPECT_TRUE(ik.column_index(coordinate).has_value()) << coordinate;
  }
  // This file's header (OpenSim 3, SIMM motion style) does not state
  // inDegrees; the SIMM header makes it degrees, and a warning says so.
  EXPECT_FALSE(ik.in_degrees_stated);
  EXPECT_TRUE(ik.in_degrees);
  // The force-plate columns repeat their names (one set per plate).
  int duplicate_warnings = 0;
  bool in_degrees_warning = false;
  for (const std::string& warning : ik.warnings) {
    if (warning.find("appears 2 times") != std::string::npos) ++duplicate_warnings;
    if (warning.find("inDegrees") != std::string::npos) in_degrees_warning = true;
  }
  EXPECT_EQ(duplicate_warnings, 9);  // ground_force_v/p xyz (6) + ground_torque_xyz (3)
  EXPECT_TRUE(in_degrees_warning);
  // Degrees indeed: the knee flexes beyond 60 (radians would stay within pi).
  EXPECT_LT(ik.column("knee_angle_r").minCoeff(), -60.0);
  // First row as printed (20 decimals, parsed correctly rounded).
  EXPECT_EQ(ik.value_at("hip_flexion_r", 0.5), 19.25296658866297500000);
  EXPECT_EQ(ik.value_at("knee_angle_r", 0.5), -19.88552911045664800000);
  // Pelvis translations are in m: the pelvis of this 1.80 m subject walks
  // about 1 m above the floor; 0.1 m covers the up-and-down of gait and the
  // model's pelvis-origin offset, while mm or cm would be off by 10x.
  EXPECT_NEAR(ik.column("pelvis_ty").mean(), 1.0, 0.1);
}

}  // namespace
}  // namespace mmm::opensim

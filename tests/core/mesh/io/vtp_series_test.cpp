#include "core/mesh/io/vtp_series.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh/io/pvd.h"
#include "core/mesh/io/vtp.h"
#include "core/mesh/io/vtp_polylines.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::mesh {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// A femur stand-in moving along x and two fibres lengthening with the frame.
IndexedMesh bone_at(int frame) {
  IndexedMesh torus = make_torus(30.0, 8.0, 16, 8);
  torus.V.col(0).array() += 1.0 / 3.0 * frame;
  return torus;
}

Polylines fibres_at(int frame) {
  Polylines fibres;
  fibres.points.resize(4, 3);
  fibres.points << 0, 0, 0,  //
      0, 0, 100.0 + frame,   //
      5, 0, 0,               //
      5, 0, 101.0 + frame;
  fibres.lines = {{0, 1}, {2, 3}};
  return fibres;
}

constexpr double kFrameTime = 0.01;  // 100 Hz motion capture

// Frames added out of time order (2, 1, 0), femur before fibres within each.
void write_three_frames(VtpSeriesWriter& series) {
  for (int frame = 2; frame >= 0; --frame) {
    VtpArrays fibre_arrays;
    fibre_arrays.cell_scalars.emplace_back("activation", Eigen::Vector2d(0.1 * frame, 0.5));
    series.add_surface(kFrameTime * frame, frame, "femur_r", bone_at(frame));
    series.add_polylines(kFrameTime * frame, frame, "soleus_r-fibres", fibres_at(frame),
                         fibre_arrays);
  }
}

TEST(VtpSeriesTest, ThreeFramesOfTwoPartsGiveSixFilesAndAnIndex) {
  test::ScratchDir scratch("vtp-series");
  VtpSeriesWriter series(scratch.path(), "walk_01");
  write_three_frames(series);
  series.finish();

  const std::vector<std::filesystem::path>& written = series.written_files();
  ASSERT_EQ(written.size(), 7U);  // 6 frames + the index
  EXPECT_EQ(written.back(), scratch / "walk_01.pvd");
  EXPECT_EQ(written.front(), scratch.path() / "walk_01" / "femur_r_0002.vtp");
  int vtp_files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(scratch / "walk_01")) {
    EXPECT_EQ(entry.path().extension(), ".vtp");
    ++vtp_files;
  }
  EXPECT_EQ(vtp_files, 6);

  const std::vector<PvdEntry> entries = read_pvd(scratch / "walk_01.pvd");
  ASSERT_EQ(entries.size(), 6U);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int frame = static_cast<int>(i / 2);
    const bool femur = i % 2 == 0;  // sorted by time, then part (femur_r seen first: part 0)
    // Same double expression as when written; exact text round trip.
    EXPECT_EQ(entries[i].time, kFrameTime * frame) << "entry " << i;
    EXPECT_EQ(entries[i].part, femur ? 0 : 1) << "entry " << i;
    EXPECT_EQ(entries[i].name, femur ? "femur_r" : "soleus_r-fibres") << "entry " << i;
    const std::string file = std::string(femur ? "femur_r" : "soleus_r-fibres") + "_000" +
                             std::to_string(frame) + ".vtp";
    EXPECT_EQ(entries[i].file, std::filesystem::path("walk_01") / file) << "entry " << i;
    EXPECT_TRUE(std::filesystem::exists(scratch.path() / entries[i].file)) << "entry " << i;
  }
}

TEST(VtpSeriesTest, FramesReadBackExactly) {
  test::ScratchDir scratch("vtp-series");
  VtpSeriesWriter series(scratch.path(), "walk");
  write_three_frames(series);
  series.finish();
  const std::vector<PvdEntry> entries = read_pvd(series.pvd_path());
  ASSERT_EQ(entries.size(), 6U);
  // Entry 2: frame 1 of the femur; entry 5: frame 2 of the fibres.
  const IndexedMesh bone = read_vtp(scratch.path() / entries[2].file);
  EXPECT_EQ(bone.V, bone_at(1).V);  // shortest round-trip text: bit for bit
  EXPECT_EQ(bone.F, bone_at(1).F);
  const Polylines fibres = read_vtp_polylines(scratch.path() / entries[5].file);
  EXPECT_EQ(fibres.points, fibres_at(2).points);
  EXPECT_EQ(fibres.lines, fibres_at(2).lines);
}

TEST(VtpSeriesTest, UnsafePartNameIsInvalidInput) {
  test::ScratchDir scratch("vtp-series");
  VtpSeriesWriter series(scratch.path(), "walk");
  for (const std::string part : {"../femur", "femur r", "", "a/b", ".."}) {
    EXPECT_THAT([&] { series.add_surface(0.0, 0, part, bone_at(0)); },
                ThrowsMessage<InvalidInputError>(
                    HasSubstr("animation part '" + part + "' is not a safe file-name fragment")))
        << part;
  }
  EXPECT_THAT([&] { VtpSeriesWriter(scratch.path(), "walk/01"); },
              ThrowsMessage<InvalidInputError>(HasSubstr("animation stem 'walk/01'")));
  EXPECT_FALSE(std::filesystem::exists(scratch / "walk"));  // nothing written
}

TEST(VtpSeriesTest, RepeatedFrameTimeOrFrameNumberIsInvalidInput) {
  test::ScratchDir scratch("vtp-series");
  VtpSeriesWriter series(scratch.path(), "walk");
  series.add_surface(0.0, 0, "femur_r", bone_at(0));
  EXPECT_THAT([&] { series.add_surface(0.5, 0, "femur_r", bone_at(0)); },
              ThrowsMessage<InvalidInputError>(HasSubstr("'femur_r' frame 0 was already added")));
  EXPECT_THAT([&] { series.add_surface(0.0, 1, "femur_r", bone_at(1)); },
              ThrowsMessage<InvalidInputError>(HasSubstr("already has a frame at time 0")));
  EXPECT_THAT([&] { series.add_surface(0.1, -1, "femur_r", bone_at(1)); },
              ThrowsMessage<InvalidInputError>(HasSubstr("has frame number -1")));
  EXPECT_EQ(series.written_files().size(), 1U);
}

TEST(VtpSeriesTest, FinishTwiceOrAddAfterFinishIsALogicError) {
  test::ScratchDir scratch("vtp-series");
  VtpSeriesWriter series(scratch.path(), "walk");
  EXPECT_THAT([&] { series.finish(); },
              ThrowsMessage<InvalidInputError>(HasSubstr("no frame was added")));
  series.add_polylines(0.0, 0, "fibres", fibres_at(0));
  series.finish();
  // InvalidInputError is a logic_error too: the messages tell the two apart.
  EXPECT_THAT([&] { series.finish(); },
              ThrowsMessage<std::logic_error>(HasSubstr("finish() called twice")));
  EXPECT_THAT([&] { series.add_polylines(1.0, 1, "fibres", fibres_at(1)); },
              ThrowsMessage<std::logic_error>(HasSubstr("after finish()")));
  EXPECT_EQ(read_pvd(series.pvd_path()).size(), 1U);
}

}  // namespace
}  // namespace mmm::mesh

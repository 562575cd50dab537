// The wrapped-motion artifact (core/wrapping/muscle_frames.h): written from a
// wrapping result at a stride, read back exactly; every kind of damage is
// refused naming the field, and a hostile count never allocates beyond the
// bytes it came with.

#include "core/wrapping/muscle_frames.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "core/errors.h"
#include "core/mesh/primitives.h"

namespace mmm::wrapping {
namespace {

// Two muscles (an icosahedron and a box) over 7 frames: each frame moves
// them and turns a bone about z.
MuscleWrapping two_muscles_seven_frames() {
  MuscleWrapping wrapped;
  wrapped.bone_names = {"femur_r", "tibia_r"};
  wrapped.times.resize(7);
  const std::vector<mesh::IndexedMesh> rest = {
      mesh::make_icosphere(0, 10.0),
      mesh::make_box(Eigen::Vector3d(2, 3, 4), Eigen::Vector3d(9, 8, 7))};
  for (std::size_t m = 0; m < rest.size(); ++m) {
    WrappedMuscle& muscle = wrapped.muscles.emplace_back();
    muscle.name = m == 0 ? "vastus_r" : "soleus_r";
    muscle.rest = rest[m];
    muscle.lines.push_back(
        {.name = muscle.name + "_line", .paths = {}, .lengths_mm = {}, .moment_arms_mm = {}});
  }
  for (int k = 0; k < 7; ++k) {
    wrapped.times(k) = 0.5 + 0.01 * k;
    std::vector<Eigen::Isometry3d> poses(2, Eigen::Isometry3d::Identity());
    poses[1].rotate(Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d::UnitZ()));
    poses[1].translation() = Eigen::Vector3d(1.0, -2.0, 0.5 * k);
    wrapped.bone_poses.push_back(poses);
    for (WrappedMuscle& muscle : wrapped.muscles) {
      muscle.positions.emplace_back((muscle.rest.V.array() + 0.25 * k).matrix().cast<float>());
      std::vector<Eigen::Vector3d> path(static_cast<std::size_t>(2 + k % 3));
      for (std::size_t i = 0; i < path.size(); ++i)
        path[i] = Eigen::Vector3d(k, static_cast<double>(i), 1.5);
      muscle.lines.front().paths.push_back(path);
    }
  }
  return wrapped;
}

TEST(MuscleFramesTest, EveryStrideThFrameIsWrittenAndReadBackExactly) {
  const MuscleWrapping wrapped = two_muscles_seven_frames();
  const MuscleFrames frames = muscle_frames(wrapped, 3, "energy");
  ASSERT_EQ(frames.frame_index, (std::vector<int>{0, 3, 6}));
  const MuscleFrames back = decode_muscle_frames(encode_muscle_frames(frames), "test");
  EXPECT_EQ(back.pathway, "energy");
  EXPECT_EQ(back.motion_frames, 7);
  EXPECT_EQ(back.frame_index, frames.frame_index);
  EXPECT_EQ(back.times, (std::vector<double>{0.5, 0.53, 0.56}));
  EXPECT_EQ(back.bone_names, wrapped.bone_names);
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Isometry3d expected = wrapped.bone_poses[3 * k][1];
    EXPECT_EQ(back.pose("tibia_r", k).matrix(), expected.matrix());
  }
  EXPECT_THROW((void)back.pose("pelvis", 0), InvalidInputError);
  ASSERT_EQ(back.muscles.size(), 2U);
  for (std::size_t m = 0; m < 2; ++m) {
    const WrappedMuscle& original = wrapped.muscles[m];
    const FramedMuscle& read = back.muscles[m];
    EXPECT_EQ(read.name, original.name);
    EXPECT_EQ(read.rest.V, original.rest.V);
    EXPECT_EQ(read.rest.F, original.rest.F);
    ASSERT_EQ(read.positions.size(), 3U);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(read.positions[k], original.positions[3 * k]);
      EXPECT_EQ(read.lines.front().paths[k], original.lines.front().paths[3 * k]);
    }
  }
  EXPECT_EQ(back.find_muscle("soleus_r"), &back.muscles[1]);
  EXPECT_EQ(back.find_muscle("nobody"), nullptr);
  // The last frame is not forced in: a stride that does not divide the
  // frames stops at the last multiple.
  EXPECT_EQ(muscle_frames(wrapped, 4, "energy").frame_index, (std::vector<int>{0, 4}));
  EXPECT_THROW((void)muscle_frames(wrapped, 0, "energy"), InvalidInputError);
}

// Bytes of a valid artifact with one value overwritten at `offset`.
template <typename T>
std::string patched(std::string bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof(T));
  return bytes;
}

void expect_refused(const std::string& bytes, const std::string& mentioning) {
  try {
    (void)decode_muscle_frames(bytes, "input 'wrapped'");
    ADD_FAILURE() << "accepted; expected an error mentioning " << mentioning;
  } catch (const InvalidInputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("input 'wrapped'"), std::string::npos) << message;
    EXPECT_NE(message.find(mentioning), std::string::npos) << message;
  }
}

TEST(MuscleFramesTest, DamagedOrHostileBytesAreRefusedNamingTheField) {
  const std::string good =
      encode_muscle_frames(muscle_frames(two_muscles_seven_frames(), 2, "volumetric"));
  expect_refused("", "header");
  expect_refused("not an artifact at all, just text", "header");
  expect_refused(patched(good, 16, std::uint32_t{9}), "version");
  // Truncated anywhere: refused, never read past the end.
  for (const std::size_t cut : {20UL, 60UL, good.size() / 2, good.size() - 1})
    expect_refused(good.substr(0, cut), "byte");
  expect_refused(good + "x", "end");
  // Offsets: magic 16, version 4, pathway 4 + 10, motion frames 4.
  const std::size_t stored_at = 16 + 4 + 4 + 10 + 4;
  expect_refused(patched(good, stored_at, std::uint32_t{4'000'000'000U}), "stored frames");
  expect_refused(patched(good, stored_at, std::uint32_t{3}), "");  // fewer than written
  // The second stored frame's index equal to the first's: out of order.
  expect_refused(patched(good, stored_at + 4 + 12, std::uint32_t{0}), "out of order");
  expect_refused(patched(good, stored_at + 4 + 4, std::numeric_limits<double>::quiet_NaN()),
                 "frame time");
  // The first bone pose's first rotation entry: not a rotation, then NaN.
  const std::size_t bones_at = stored_at + 4 + std::size_t{4} * 12;
  const std::size_t poses_at = bones_at + 4 + (4 + 7) + (4 + 7);
  expect_refused(patched(good, poses_at, 2.0), "not a rotation");
  expect_refused(patched(good, poses_at, std::numeric_limits<double>::infinity()), "finite");
  // The first muscle: a vertex count beyond the bytes, then a face corner
  // beyond its vertices.
  const std::size_t muscle_at = poses_at + std::size_t{4} * 2 * 12 * 8 + 4;
  const std::size_t vertices_at = muscle_at + 4 + 8;  // "vastus_r"
  expect_refused(patched(good, vertices_at, std::uint32_t{2'000'000'000U}), "vertices");
  const std::size_t faces_at =
      vertices_at + 8 + std::size_t{12} * 3 * 8;  // an icosahedron's 12 vertices
  expect_refused(patched(good, faces_at, std::uint32_t{12}), "refers to vertex 12 of 12");
}

}  // namespace
}  // namespace mmm::wrapping

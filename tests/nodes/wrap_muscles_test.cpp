// Node wrap_muscles: a toy leg driven by the real walking trial (retargeted
// by fuse_motion) has its muscle wrapped frame by frame with the volume held
// and no vertex in a bone, and every output in a format its tool opens; a
// motion of an OpenSim model is refused with a hint.

#include "nodes/wrap_muscles.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/mesh/io/pvd.h"
#include "nodes/fuse_motion.h"
#include "tests/nodes/node_harness.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::nodes {
namespace {

using workflow::PortType;

std::filesystem::path pipelines() { return mmm::test::data_dir() / "gait2392" / "Pipelines"; }

TEST(WrapMusclesNodeTest, WrapsTheToyLegsMuscleOverARetargetedWalk) {
  test::NodeHarness harness;
  mmm::test::ToyLeg leg = mmm::test::toy_leg();
  // Three pelvis markers, as retargeting measures the patient against the trial.
  for (const auto& [name, x] : {std::pair{"R.ASIS", 150.0}, {"L.ASIS", -60.0}}) {
    leg.atlas.markers.push_back({name, "pelvis", Eigen::Vector3d(x, 30, 20), true});
  }
  leg.atlas.markers.push_back({"V.Sacral", "pelvis", Eigen::Vector3d(45, -120, 30), true});
  atlas::write_atlas_with_meshes(leg.atlas, leg.meshes, harness.folder() / "toy");
  const workflow::ArtifactRef atlas =
      harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"));
  const auto fused = harness.run<FuseMotion>(
      {{"atlas", atlas},
       {"model",
        harness.add_file(PortType::kFile, pipelines() / "reference" / "subject01_simbody.osim")},
       {"trial", harness.add_file(PortType::kFile, pipelines() / "subject01_walk1.trc")}},
      {{"start_time", 0.5}, {"end_time", 0.7}});
  const auto outputs = harness.run<WrapMuscles>({{"atlas", atlas}, {"motion", fused.at("motion")}},
                                                {{"animation_stride", std::int64_t{2}}});
  const nlohmann::json report =
      nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  const int frames = report["frames"];
  EXPECT_GE(frames, 10);
  EXPECT_LT(report["max_abs_volume_error_percent"].get<double>(), 1e-5);
  EXPECT_LE(report["max_depth_mm"].get<double>(), 0.1 + 1e-9);  // the contact tolerance
  EXPECT_EQ(report["unconverged_muscle_frames"], 0);
  ASSERT_EQ(report["muscles"].size(), leg.atlas.muscles.size());
  // One metrics row per muscle and frame, one line row per line and frame.
  const std::string metrics = mmm::test::read_text(outputs.at("metrics").path);
  EXPECT_EQ(std::count(metrics.begin(), metrics.end(), '\n'),
            1 + frames * static_cast<long>(leg.atlas.muscles.size()));
  EXPECT_EQ(metrics.rfind("muscle,frame,time_s,volume_error_percent,max_depth_mm", 0), 0U);
  const std::string lines = mmm::test::read_text(outputs.at("lines").path);
  EXPECT_NE(lines.find("moment_arm_knee_angle_r_mm"), std::string::npos);
  EXPECT_EQ(mmm::test::read_text(outputs.at("plot").path).rfind("<svg", 0), 0U);
  // ParaView: every other frame of the muscle, the bones and the lines.
  const std::filesystem::path animation = harness.folder() / "animation";
  unpack_directory(mmm::test::read_text(outputs.at("animation").path), animation, "animation");
  const std::vector<mesh::PvdEntry> entries = mesh::read_pvd(animation / "wrapping.pvd");
  const std::string muscle = leg.atlas.muscles.front().name;
  long muscle_frames = 0;
  for (const mesh::PvdEntry& entry : entries) {
    if (entry.file.filename().string().rfind(muscle + "_", 0) == 0) ++muscle_frames;
  }
  EXPECT_EQ(muscle_frames, (frames + 1) / 2);
  EXPECT_TRUE(std::filesystem::exists(animation / "wrapping" / "action_lines_0000.vtp"));
  EXPECT_TRUE(std::filesystem::exists(animation / "wrapping" / "femur_r_0000.vtp"));
}

TEST(WrapMusclesNodeTest, AMotionOfAnOpenSimModelIsRefusedWithAHint) {
  test::NodeHarness harness;
  const mmm::test::ToyLeg leg = mmm::test::toy_leg();
  atlas::write_atlas_with_meshes(leg.atlas, leg.meshes, harness.folder() / "toy");
  const auto fused = harness.run<FuseMotion>(
      {{"model",
        harness.add_file(PortType::kFile, pipelines() / "reference" / "subject01_simbody.osim")},
       {"trial", harness.add_file(PortType::kFile, pipelines() / "subject01_walk1.trc")}},
      {{"start_time", 0.5}, {"end_time", 0.55}});
  try {
    harness.run<WrapMuscles>(
        {{"atlas", harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"))},
         {"motion", fused.at("motion")}});
    FAIL() << "wrapped an atlas with an OpenSim model's motion";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("give fuse_motion the atlas input"), std::string::npos)
        << error.what();
  }
}

TEST(WrapMusclesNodeTest, AMotionThatIsNotJsonIsRefusedNamingTheInput) {
  test::NodeHarness harness;
  const mmm::test::ToyLeg leg = mmm::test::toy_leg();
  atlas::write_atlas_with_meshes(leg.atlas, leg.meshes, harness.folder() / "toy");
  EXPECT_THROW(
      harness.run<WrapMuscles>(
          {{"atlas", harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"))},
           {"motion", harness.add(PortType::kBonePoses, "not json {")}}),
      InvalidInputError);
}

}  // namespace
}  // namespace mmm::nodes

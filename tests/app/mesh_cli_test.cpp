// End-to-end checks of `mmm mesh ...`: run the real executable, read its
// output and exit code the way a user or a script would.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "core/mesh/io/mesh_io.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::app {
namespace {

using ::testing::HasSubstr;

using test::CommandResult;
using test::run_mmm;

// Everything the command printed, for message checks.
std::string printed(const CommandResult& result) { return result.out + result.err; }

TEST(MeshCliTest, InfoJsonOnGluteusMediusReportsAClosedMeshAndItsVolume) {
  const auto file = test::data_dir() / "vhf/Right/VHF_Right_Muscle_GluteusMedius_smooth.stl";
  const CommandResult result = run_mmm("mesh info " + file.string() + " --json");
  ASSERT_EQ(result.exit_code, 0) << printed(result);
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_TRUE(json["closed"].get<bool>());
  EXPECT_TRUE(json["watertight"].get<bool>());
  EXPECT_TRUE(json["outward_oriented"].get<bool>());
  // Adult gluteus medius: roughly 150-600 cm^3 across published MRI studies.
  const double volume = json["volume"].get<double>();
  EXPECT_GT(volume, 150e3);
  EXPECT_LT(volume, 600e3);
  EXPECT_GT(json["faces"].get<int>(), 1000);
}

TEST(MeshCliTest, InfoTextOnPrimitiveShowsExactVolume) {
  const test::ScratchDir dir("cli-info");
  mesh::write_mesh(mesh::make_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(10, 20, 30)),
                   dir / "box.ply");
  const CommandResult result = run_mmm("mesh info " + (dir / "box.ply").string());
  ASSERT_EQ(result.exit_code, 0) << printed(result);
  EXPECT_THAT(printed(result), HasSubstr("volume      6000.0 mm^3"));
  EXPECT_THAT(printed(result), HasSubstr("closed      yes"));
}

TEST(MeshCliTest, MissingFileFailsWithItsPath) {
  const CommandResult result = run_mmm("mesh info /nonexistent/muscle.stl");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(printed(result), HasSubstr("/nonexistent/muscle.stl"));
}

TEST(MeshCliTest, UsageErrorsExitWithTwo) {
  EXPECT_EQ(run_mmm("mesh info").exit_code, 2);
  EXPECT_EQ(run_mmm("no-such-command").exit_code, 2);
  EXPECT_EQ(run_mmm("mesh decimate a.stl b.stl --faces 2").exit_code, 2);
}

TEST(MeshCliTest, ConvertWritesAReadableFileInMillimetres) {
  const test::ScratchDir dir("cli-convert");
  const auto femur = test::data_dir() / "gait2392/Geometry/femur_r.vtp";
  const auto out = dir / "femur_mm.stl";
  const CommandResult result =
      run_mmm("mesh convert " + femur.string() + " " + out.string() + " --scale 1000");
  ASSERT_EQ(result.exit_code, 0) << printed(result);
  const mesh::IndexedMesh converted = mesh::read_mesh(out);
  EXPECT_EQ(converted.num_faces(), 908);
  // A femur is 350-500 mm long; in metres it would be below 1.
  const double length =
      (converted.V.colwise().maxCoeff() - converted.V.colwise().minCoeff()).maxCoeff();
  EXPECT_GT(length, 350.0);
  EXPECT_LT(length, 500.0);
}

TEST(MeshCliTest, SurveyOfGait2392WritesReportAndVtpCopies) {
  const test::ScratchDir dir("cli-survey");
  const auto geometry = test::data_dir() / "gait2392/Geometry";
  const CommandResult result =
      run_mmm("mesh survey " + geometry.string() + " --scale 1000 --out " + dir.path().string());
  ASSERT_EQ(result.exit_code, 0) << printed(result);
  const auto json = nlohmann::json::parse(test::read_text(dir / "survey.json"));
  ASSERT_EQ(json.size(), 10U);  // the ten .vtp files of the model
  for (const auto& entry : json) {
    const std::string name = entry["file"].get<std::string>();
    EXPECT_FALSE(entry.contains("error")) << name;
    std::string stem = name.substr(0, name.size() - 4);
    EXPECT_TRUE(std::filesystem::exists(dir / "vtp" / (stem + ".vtp"))) << name;
  }
}

}  // namespace
}  // namespace mmm::app

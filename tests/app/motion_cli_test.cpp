// Motion fusion from the command line: a study of
// schemas/examples/motion_fusion.yaml runs subject01's walk through
// OpenSim's subject model and exports every output in the format its tool
// opens (.mot, .svg, .csv, .json, a ParaView .pvd folder); a study of
// schemas/examples/retarget_motion.yaml drives a patient atlas with it.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/mesh/io/pvd.h"
#include "core/opensim/mot.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm {
namespace {

namespace fs = std::filesystem;
using test::CommandResult;
using test::run_mmm;

TEST(MotionCliTest, TheWalkThroughOpenSimsModelAgreesWithOpenSimAndIsExported) {
  test::ScratchDir dir("motion-cli");
  const fs::path study = dir / "walk";
  const CommandResult created = run_mmm(
      "study create " + study.string() + " -w " +
      (test::source_dir() / "schemas/examples/motion_fusion.yaml").string() + " --input model=" +
      (test::gait2392_pipelines() / "reference" / "subject01_simbody.osim").string() +
      " --input trial=" + (test::gait2392_pipelines() / "subject01_walk1.trc").string() +
      " --input reference=" +
      (test::gait2392_pipelines() / "reference" / "subject01_walk1_ik.mot").string());
  ASSERT_EQ(created.exit_code, 0) << created.err;
  const CommandResult ran = run_mmm("run " + study.string() + " -q");
  ASSERT_EQ(ran.exit_code, 0) << ran.out << ran.err;
  const fs::path outputs = study / "outputs";
  const auto report = nlohmann::json::parse(test::read_text(outputs / "report.json"));
  EXPECT_EQ(report["fit"]["frames"], 121);  // 0.5-2.5 s at 60 Hz, as the issue compares
  for (const auto& row : report["reference_comparison"]) {
    const std::string name = row["coordinate"];
    if (name.starts_with("hip") || name.starts_with("knee") || name.starts_with("ankle")) {
      // The limits are 2 and 3 degrees; the default smoother stays
      // within a tenth of a degree of OpenSim's unfiltered answer.
      EXPECT_LT(row["rms"].get<double>(), 0.2) << name;
    }
  }
  EXPECT_EQ(opensim::read_mot(outputs / "angles.mot").num_rows(), 121);
  EXPECT_TRUE(test::read_text(outputs / "angle_plot.svg").find("<svg") != std::string::npos);
  EXPECT_EQ(mesh::read_pvd(outputs / "animation" / "motion.pvd").size(), 121u);
  EXPECT_TRUE(fs::exists(outputs / "points.csv"));
  EXPECT_TRUE(fs::exists(outputs / "motion.json"));
}

}  // namespace
}  // namespace mmm

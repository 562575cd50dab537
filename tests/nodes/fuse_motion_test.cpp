// Node fuse_motion: OpenSim's subject model driven by the real walking
// trial agrees with OpenSim's IK and writes every output in a format its
// tool opens; a patient's atlas gets the motion by retargeting; bad inputs
// fail with a hint.

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <nlohmann/json.hpp>

#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/mesh/io/pvd.h"
#include "core/motion/motion_io.h"
#include "core/opensim/mot.h"
#include "nodes/fuse_motion.h"
#include "tests/nodes/node_harness.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"
#include "workflow/definition/node_catalog.h"

namespace mmm::nodes {
namespace {

using workflow::PortType;

workflow::ArtifactRef add_file(test::NodeHarness& harness, const std::filesystem::path& file) {
  return harness.add(PortType::kFile, mmm::test::read_text(file));
}

// Golden spec: a change of a port, a parameter or a default must show here.
TEST(FuseMotionNodeTest, SpecIsPinned) {
  EXPECT_EQ(workflow::node_spec_json(FuseMotion::spec()).dump(2), R"json({
  "description": "Drive a model with a marker trial: Kabsch per body, Ceres kinematic-chain fit, Kalman filter with RTS smoother and joint limits; optional marker placement from a static trial and retargeting from the trial subject's model to the patient's atlas",
  "inputs": [
    {
      "description": "Marker trial (.trc); gaps and NaN frames allowed",
      "name": "trial",
      "required": true,
      "type": "File"
    },
    {
      "description": "The patient's (scaled) atlas to drive",
      "name": "atlas",
      "required": false,
      "type": "Atlas"
    },
    {
      "description": "OpenSim model (.osim): driven itself, or with an atlas the trial subject's model the motion is fitted to and retargeted from",
      "name": "model",
      "required": false,
      "type": "File"
    },
    {
      "description": "Marker mapping (YAML, schemas/motion/); default: gait2392's with OpenSim's IK weights",
      "name": "mapping",
      "required": false,
      "type": "File"
    },
    {
      "description": "Standing trial (.trc): the fitted model's markers are placed where the subject wore them",
      "name": "static_trial",
      "required": false,
      "type": "File"
    },
    {
      "description": "Joint angles to compare with (.mot, e.g. OpenSim IK)",
      "name": "reference",
      "required": false,
      "type": "File"
    }
  ],
  "manual": false,
  "name": "fuse_motion",
  "outputs": [
    {
      "description": "Per-frame coordinates, body poses and marker errors",
      "name": "motion",
      "type": "BonePoses"
    },
    {
      "description": "Joint angles (.mot; deg and m, OpenSim's conventions)",
      "name": "angles",
      "type": "File"
    },
    {
      "description": "CSV of every landmark, attachment area, action-line point and marker per frame",
      "name": "points",
      "type": "File"
    },
    {
      "description": "Markers, residuals, filter, retargeting, reference comparison",
      "name": "report",
      "type": "Report"
    },
    {
      "description": "SVG of the joint angles over time",
      "name": "plot",
      "type": "File"
    },
    {
      "description": "Folder bundle of a ParaView animation (.pvd + .vtp per frame)",
      "name": "animation",
      "type": "File"
    }
  ],
  "params": [
    {
      "default": 0.0,
      "description": "First time fused (s); 0: the trial's start",
      "min": 0.0,
      "name": "start_time",
      "type": "number",
      "unit": "s"
    },
    {
      "default": -1.0,
      "description": "Last time fused (s); negative: the trial's end",
      "name": "end_time",
      "type": "number",
      "unit": "s"
    },
    {
      "choices": [
        "none",
        "forward",
        "smoother"
      ],
      "default": "smoother",
      "description": "Temporal filter: none (per-frame IK as OpenSim), forward Kalman, or Kalman with a Rauch-Tung-Striebel smoother (no lag)",
      "name": "filter",
      "type": "enum"
    },
    {
      "default": 30.0,
      "description": "Filter process noise of angles (white acceleration, rad/s^2 per sqrt(Hz))",
      "max": 1000000.0,
      "min": 0.001,
      "name": "angular_acceleration_sd",
      "type": "number"
    },
    {
      "default": 3000.0,
      "description": "Filter process noise of translations (mm/s^2 per sqrt(Hz))",
      "max": 100000000.0,
      "min": 0.001,
      "name": "linear_acceleration_sd",
      "type": "number"
    },
    {
      "default": 5.0,
      "description": "Noise of a weight-1 marker, as the filter assumes it",
      "max": 100.0,
      "min": 0.01,
      "name": "marker_noise_mm",
      "type": "number",
      "unit": "mm"
    },
    {
      "default": true,
      "description": "Keep clamped coordinates inside their ranges",
      "name": "joint_limits",
      "type": "bool"
    },
    {
      "default": true,
      "description": "Retargeting: shift the patient vertically so that its feet reach the ground as low as the subject's",
      "name": "keep_ground_contact",
      "type": "bool"
    },
    {
      "default": "lod1",
      "description": "Atlas mesh level drawn in the animation",
      "name": "mesh_level",
      "type": "string"
    }
  ],
  "version": 1
})json");
}

TEST(FuseMotionNodeTest, DrivesOpenSimsSubjectModelAsOpenSimDoes) {
  test::NodeHarness harness;
  const auto outputs = harness.run<FuseMotion>(
      {{"model", add_file(harness, mmm::test::gait2392_pipelines() / "reference" /
                                       "subject01_simbody.osim")},
       {"trial", add_file(harness, mmm::test::gait2392_pipelines() / "subject01_walk1.trc")},
       {"reference", add_file(harness, mmm::test::gait2392_pipelines() / "reference" /
                                           "subject01_walk1_ik.mot")}},
      {{"start_time", 0.5}, {"end_time", 1.0}, {"filter", std::string("none")}});
  const nlohmann::json report =
      nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  EXPECT_EQ(report["fit"]["frames"], 31);  // 0.5-1.0 s at 60 Hz
  int compared = 0;
  for (const nlohmann::json& row : report["reference_comparison"]) {
    const std::string coordinate = row["coordinate"];
    if (coordinate == "knee_angle_r" || coordinate == "hip_flexion_r" ||
        coordinate == "ankle_angle_r") {
      // Same objective, same weights: OpenSim's answer to its accuracy
      // (1e-5), far inside the issue's 2 degrees.
      EXPECT_LT(row["rms"].get<double>(), 0.1) << coordinate;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 3);
  // The .mot reads back in degrees; the motion JSON reads back whole.
  const opensim::StorageTable angles = opensim::read_mot(outputs.at("angles").path);
  EXPECT_TRUE(angles.in_degrees);
  EXPECT_EQ(angles.num_rows(), 31);
  const motion::FusedMotion motion = motion::motion_from_json(
      nlohmann::json::parse(mmm::test::read_text(outputs.at("motion").path)), "motion");
  EXPECT_EQ(motion.body_names.size(), 12u);
  EXPECT_EQ(motion.poses.size(), 31u);
  // The plot is an SVG document; the animation a ParaView series.
  tinyxml2::XMLDocument svg;
  ASSERT_EQ(svg.LoadFile(outputs.at("plot").path.c_str()), tinyxml2::XML_SUCCESS);
  EXPECT_STREQ(svg.RootElement()->Name(), "svg");
  const std::filesystem::path animation = harness.folder() / "animation";
  unpack_directory(mmm::test::read_text(outputs.at("animation").path), animation, "animation");
  const std::vector<mesh::PvdEntry> entries = mesh::read_pvd(animation / "motion.pvd");
  EXPECT_EQ(entries.size(), 31u);  // the stick figure, per frame
  const std::string points = mmm::test::read_text(outputs.at("points").path);
  EXPECT_TRUE(points.starts_with("frame,time_s,kind,element,name,bone,x_mm,y_mm,z_mm,active\n"));
}

TEST(FuseMotionNodeTest, RetargetsTheSubjectsMotionToAPatientAtlas) {
  test::NodeHarness harness;
  mmm::test::ToyLeg leg = mmm::test::toy_leg();
  // Three pelvis markers so that the patient can be measured against the trial.
  for (const auto& [name, x] : {std::pair{"R.ASIS", 150.0}, {"L.ASIS", -60.0}}) {
    leg.atlas.markers.push_back({name, "pelvis", Eigen::Vector3d(x, 30, 20), true});
  }
  leg.atlas.markers.push_back({"V.Sacral", "pelvis", Eigen::Vector3d(45, -120, 30), true});
  atlas::write_atlas_with_meshes(leg.atlas, leg.meshes, harness.folder() / "toy");
  const auto outputs = harness.run<FuseMotion>(
      {{"atlas", harness.add(PortType::kAtlas, pack_directory(harness.folder() / "toy"))},
       {"model", add_file(harness, mmm::test::gait2392_pipelines() / "reference" /
                                       "subject01_simbody.osim")},
       {"trial", add_file(harness, mmm::test::gait2392_pipelines() / "subject01_walk1.trc")}},
      {{"start_time", 0.5}, {"end_time", 0.7}, {"mesh_level", std::string("lod1")}});
  const nlohmann::json report =
      nlohmann::json::parse(mmm::test::read_text(outputs.at("report").path));
  ASSERT_TRUE(report.contains("retargeting"));
  const std::vector<std::string> transferred = report["retargeting"]["transferred"];
  EXPECT_NE(std::find(transferred.begin(), transferred.end(), "knee_angle_r"), transferred.end());
  EXPECT_GT(report["retargeting"]["leg_length_ratio"].get<double>(), 0.5);
  // The patient's bones, action lines and stick figure per frame.
  const std::filesystem::path animation = harness.folder() / "animation";
  unpack_directory(mmm::test::read_text(outputs.at("animation").path), animation, "animation");
  EXPECT_TRUE(std::filesystem::exists(animation / "motion" / "femur_r_0000.vtp"));
  EXPECT_TRUE(std::filesystem::exists(animation / "motion" / "action_lines_0000.vtp"));
  const std::string points = mmm::test::read_text(outputs.at("points").path);
  EXPECT_NE(points.find(",landmark,femoral_head_centre_r,"), std::string::npos);
  EXPECT_NE(points.find(",path_point,vastus_r/vastus_r,"), std::string::npos);
}

TEST(FuseMotionNodeTest, NothingToDriveIsAnErrorWithAHint) {
  test::NodeHarness harness;
  try {
    harness.run<FuseMotion>(
        {{"trial", add_file(harness, mmm::test::gait2392_pipelines() / "subject01_walk1.trc")}});
    FAIL() << "ran without a model";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("connect 'atlas'"), std::string::npos);
  }
}

}  // namespace
}  // namespace mmm::nodes

// End-to-end checks of `mmm validate`, `mmm graph` and `mmm nodes`: run the
// real executable (with the node types of nodes/) the way a user would.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/test_data.h"

namespace mmm::app {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

using test::CommandResult;
using test::run_mmm;

std::string example() {
  return (mmm::test::source_dir() / "schemas/examples/mesh_demo.yaml").string();
}

std::string malformed(const std::string& name) {
  return (mmm::test::source_dir() / "tests/workflow/definition/malformed" / name).string();
}

TEST(WorkflowCliTest, ValidateAcceptsTheExample) {
  const CommandResult result = run_mmm("validate " + example());
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out, example() + ": valid (3 nodes)\n");
  EXPECT_EQ(result.err, "");
}

TEST(WorkflowCliTest, ValidatePrintsEveryLocatedProblemAndExitsOne) {
  const std::string file = malformed("many_problems.yaml");
  const CommandResult result = run_mmm("validate " + file);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(result.out, "");
  EXPECT_THAT(result.err, HasSubstr(file + ":10:22: parameter 'format' of node 'load': expects "
                                           "one of {stl, obj, ply, off, vtp}, got 'stp'\n"));
  EXPECT_THAT(result.err,
              HasSubstr(file + ":17:20: input 'mesh' of node 'measure' refers to unknown node "
                               "'simplyfy'; did you mean 'simplify'?"));
  EXPECT_THAT(result.err, HasSubstr(file + ":23:5: nodes[4]: unknown key 'extra'"));
  EXPECT_THAT(result.err, HasSubstr(file + ": 10 problem(s)\n"));
}

TEST(WorkflowCliTest, ValidateUsesTheRealNodeTypes) {
  // The fixture's takes_integer node exists only in the test registry of
  // tests/workflow: the executable does not know it.
  const std::string file = malformed("study_default_wrong_type.yaml");
  const CommandResult result = run_mmm("validate " + file);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr(file + ":7:14: default of study input 'target' must be "
                                           "Integer, got number 2000.5\n"));
  EXPECT_THAT(result.err,
              HasSubstr(file + ":13:11: node 'wants_target': unknown node type 'takes_integer'"));
}

TEST(WorkflowCliTest, ValidateMissingFileExitsOne) {
  const CommandResult result = run_mmm("validate /nonexistent/wf.yaml");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("/nonexistent/wf.yaml: no such file\n"));
}

// A node that contains itself through an alias used to crash `mmm validate`,
// and ~700 bytes of nested aliases kept it busy for minutes.
TEST(WorkflowCliTest, SelfReferencingAndExplodingAliasesAreReportedNotFollowed) {
  const CommandResult self = run_mmm("validate " + malformed("self_alias.yaml"));
  EXPECT_EQ(self.exit_code, 1);
  EXPECT_THAT(self.err, HasSubstr("self_alias.yaml:3:12: YAML syntax error: an alias names a node "
                                  "that contains it"));
  const CommandResult bomb = run_mmm("validate " + malformed("alias_bomb.yaml"));
  EXPECT_EQ(bomb.exit_code, 1);
  EXPECT_THAT(bomb.err, HasSubstr("more than 2000000 nodes"));
}

TEST(WorkflowCliTest, GraphPrintsDotForAValidWorkflow) {
  const CommandResult result = run_mmm("graph " + example());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, ::testing::StartsWith("digraph \"mesh_demo\" {\n"));
  EXPECT_THAT(result.out, HasSubstr("\"load\" -> \"simplify\" [label=\"mesh -> mesh\\nMesh\"];"));
  EXPECT_THAT(result.out, HasSubstr("\"study.surface\" [shape=ellipse"));
  EXPECT_THAT(result.out, ::testing::EndsWith("}\n"));
}

TEST(WorkflowCliTest, GraphOfAnInvalidWorkflowPrintsDiagnosticsOnly) {
  const std::string file = malformed("cycle.yaml");
  const CommandResult result = run_mmm("graph " + file);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(result.out, "");  // nothing for dot to misread
  EXPECT_THAT(result.err, HasSubstr(file + ":9:9: cycle: coarse -> coarsest -> coarser -> coarse"));
}

TEST(WorkflowCliTest, NodesListsTypesPortsAndParameters) {
  const CommandResult result = run_mmm("nodes");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("decimate_mesh (version 1)\n"));
  EXPECT_THAT(result.out, HasSubstr("load_mesh (version 1)\n"));
  EXPECT_THAT(result.out, HasSubstr("measure_mesh (version 1)\n"));
  EXPECT_THAT(result.out, HasSubstr("(default 60 deg, range [1, 180])"));
  EXPECT_THAT(result.out, HasSubstr("one of {stl, obj, ply, off, vtp}"));
  EXPECT_THAT(result.out,
              ::testing::EndsWith("workflow file format: schemas/workflow.schema.yaml (examples in "
                                  "schemas/examples/)\n"));
}

TEST(WorkflowCliTest, NodesJsonIsMachineReadable) {
  const CommandResult result = run_mmm("nodes --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  std::vector<std::string> names;
  for (const auto& type : json["node_types"]) {
    names.push_back(type["name"].get<std::string>());
    EXPECT_EQ(type["manual"].get<bool>(),
              type["name"] == "landmark_station" || type["name"] == "outline_review")
        << type["name"];
  }
  EXPECT_EQ(names, (std::vector<std::string>{
                       "build_hulls", "build_muscle_lattice", "decimate_mesh", "decompose_fibres",
                       "fit_bone_outlines", "fuse_motion", "import_markups", "landmark_report",
                       "landmark_station", "load_mesh", "load_radiographs", "measure_mesh",
                       "outline_review", "scale_atlas", "simulate_muscles",
                       "static_trial_landmarks", "wrap_muscles"}))
      << "sorted by name";
  const auto& decimate = json["node_types"][2];
  EXPECT_EQ(decimate["name"], "decimate_mesh");
  EXPECT_EQ(decimate["inputs"][0]["type"], "Mesh");
  EXPECT_EQ(decimate["params"][0]["name"], "target_faces");
  EXPECT_EQ(decimate["params"][0]["default"], 5000);
  EXPECT_EQ(decimate["params"][0]["min"], 4);
  EXPECT_EQ(json["schema"], "schemas/workflow.schema.yaml");
}

TEST(WorkflowCliTest, UsageErrorsExitWithTwo) {
  EXPECT_EQ(run_mmm("validate").exit_code, 2);
  EXPECT_EQ(run_mmm("graph").exit_code, 2);
  EXPECT_EQ(run_mmm("nodes --yaml").exit_code, 2);
}

TEST(WorkflowCliTest, MissingSchemaIsAnErrorNamingMmmSchemaDir) {
  const CommandResult result = run_mmm("validate " + example(), "MMM_SCHEMA_DIR=/nonexistent");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("MMM_SCHEMA_DIR"));
  EXPECT_THAT(result.out, Not(HasSubstr("valid")));
}

}  // namespace
}  // namespace mmm::app

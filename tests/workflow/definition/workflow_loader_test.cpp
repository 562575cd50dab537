#include "workflow/definition/workflow_loader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "tests/workflow/definition/test_node_types.h"

namespace mmm::workflow {
namespace {

using ::testing::HasSubstr;

// One malformed fixture: the single diagnostic it must produce.
struct MalformedCase {
  const char* file;
  int line;
  int column;
  const char* message;  // a substring of the message
};

void PrintTo(const MalformedCase& c, std::ostream* out) { *out << c.file; }

class MalformedWorkflowTest : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(MalformedWorkflowTest, ReportsExactlyItsProblemAtItsPosition) {
  const MalformedCase& c = GetParam();
  const NodeRegistry registry = test::make_test_registry();
  const auto path = test::malformed_dir() / c.file;
  const LoadResult result = load_workflow(path, registry);
  ASSERT_EQ(result.diagnostics.size(), 1U) << [&] {
    std::string all;
    for (const auto& d : result.diagnostics) all += d.text() + "\n";
    return all;
  }();
  const Diagnostic& d = result.diagnostics[0];
  EXPECT_EQ(d.file, path.string());
  EXPECT_EQ(d.line, c.line);
  EXPECT_EQ(d.column, c.column);
  EXPECT_THAT(d.message, HasSubstr(c.message));
  EXPECT_FALSE(result.valid());
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, MalformedWorkflowTest,
    ::testing::Values(
        // The file itself.
        MalformedCase{"empty.yaml", 1, 1, "the file is empty"},
        MalformedCase{"comments_only.yaml", 1, 1, "holds only comments"},
        MalformedCase{"not_yaml.yaml", 1, 1, "not a workflow file: the top level is string"},
        MalformedCase{"yaml_syntax.yaml", 7, 11, "YAML syntax error: end of map flow not found"},
        MalformedCase{"two_documents.yaml", 8, 1, "holds 2 YAML documents"},
        MalformedCase{"self_alias.yaml", 3, 12, "an alias names a node that contains it"},
        MalformedCase{"alias_bomb.yaml", 10, 10, "more than 2000000 nodes (an alias bomb?)"},
        // Structure (the schema).
        MalformedCase{"missing_nodes.yaml", 1, 1, "top level: missing required key 'nodes'"},
        MalformedCase{"wrong_version.yaml", 1, 15, "mmm_workflow: expected 1, got integer 2"},
        MalformedCase{"unknown_key.yaml", 8, 5,
                      "nodes[0]: unknown key 'param'; did you mean 'params'?"},
        MalformedCase{"bad_identifier.yaml", 6, 9,
                      "nodes[0].id: 'Load-Mesh' does not match the pattern ^[a-z][a-z0-9_]*$"},
        MalformedCase{"bad_reference_syntax.yaml", 11, 20,
                      "nodes[1].inputs.mesh: 'load/mesh' does not match the pattern"},
        MalformedCase{"duplicate_key.yaml", 8, 27, "duplicate key 'format' (first at 8:14)"},
        // Node types and parameters.
        MalformedCase{"unknown_node_type.yaml", 10, 11,
                      "node 'simplify': unknown node type 'decimate_meshes'; did you mean "
                      "decimate_mesh?"},
        MalformedCase{"unknown_parameter.yaml", 10, 7,
                      "node 'load' (load_mesh) has no parameter 'scael'; did you mean 'scale'? "
                      "(parameters: format, scale)"},
        MalformedCase{"param_wrong_type.yaml", 11, 28,
                      "parameter 'target_faces' of node 'simplify': expects an integer, got "
                      "'2000'"},
        MalformedCase{"param_out_of_range.yaml", 13, 29,
                      "parameter 'max_normal_deviation' of node 'simplify': value 270 is outside "
                      "the range [1, 180]"},
        MalformedCase{"param_bad_choice.yaml", 8, 22,
                      "expects one of {stl, obj, ply, off, vtp}, got 'step'"},
        // Ports and connections.
        MalformedCase{"missing_required_input.yaml", 9, 5,
                      "node 'simplify' (decimate_mesh): required input 'mesh' (Mesh) is not "
                      "connected"},
        MalformedCase{"unknown_input_port.yaml", 10, 7,
                      "node 'load' (load_mesh) has no input 'mesh' (inputs: file)"},
        MalformedCase{"dangling_node.yaml", 11, 20,
                      "input 'mesh' of node 'simplify' refers to unknown node 'lod'; did you "
                      "mean 'load'?"},
        MalformedCase{"dangling_port.yaml", 11, 20,
                      "node 'load' (load_mesh) has no output 'meshes'; did you mean 'mesh'?"},
        MalformedCase{"unknown_study_input.yaml", 8, 20,
                      "refers to unknown study input 'surfac'; did you mean 'surface'?"},
        MalformedCase{"type_mismatch.yaml", 14, 20,
                      "input 'mesh' of node 'simplify' expects Mesh, got Report from "
                      "'measure.report'"},
        MalformedCase{"study_type_mismatch.yaml", 8, 20,
                      "input 'file' of node 'load' expects File, got Mesh from 'study.surface'"},
        MalformedCase{"input_connected_twice.yaml", 16, 7,
                      "input 'mesh' of node 'simplify' is connected twice (first to 'load.mesh' "
                      "at 15:7)"},
        MalformedCase{"unknown_output_port.yaml", 14, 11,
                      "output 'report' refers to 'measure.reprot', but node 'measure' "
                      "(measure_mesh) has no output 'reprot'"},
        // Node ids and the graph.
        MalformedCase{"duplicate_node_id.yaml", 9, 9,
                      "duplicate node id 'load' (first defined at 6:9)"},
        MalformedCase{"reserved_node_id.yaml", 6, 9, "node id 'study' is reserved"},
        MalformedCase{"cycle.yaml", 9, 9, "cycle: coarse -> coarsest -> coarser -> coarse"},
        // Study inputs.
        MalformedCase{"unused_study_input.yaml", 5, 3,
                      "study input 'target' is not used by any node"},
        MalformedCase{"study_default_wrong_type.yaml", 7, 14,
                      "default of study input 'target' must be Integer, got number 2000.5"},
        MalformedCase{"study_default_on_file.yaml", 6, 14,
                      "study input 'surface' of type File cannot have a default"},
        MalformedCase{"unknown_port_type.yaml", 4, 19,
                      "study input 'surface': unknown port type 'Surface' (port types: Number"}),
    [](const ::testing::TestParamInfo<MalformedCase>& param_info) {
      std::string name = param_info.param.file;
      return name.substr(0, name.find('.'));
    });

TEST(WorkflowLoaderTest, ManyProblemsAreAllReportedInFileOrder) {
  const NodeRegistry registry = test::make_test_registry();
  const auto path = test::malformed_dir() / "many_problems.yaml";
  const LoadResult result = load_workflow(path, registry);
  std::vector<std::string> lines;
  const std::string prefix = path.string() + ":";
  for (const Diagnostic& d : result.diagnostics) lines.push_back(d.text().substr(prefix.size()));
  using ::testing::StartsWith;
  EXPECT_THAT(lines,
              ::testing::ElementsAre(
                  StartsWith("6:3: study input 'spare' is not used by any node"),
                  StartsWith("10:22: parameter 'format' of node 'load': expects one of"),
                  StartsWith("10:34: parameter 'scale' of node 'load': value 0 is outside the "
                             "range [0.0001, 1000000]"),
                  StartsWith("12:5: node 'simplify' (decimate_mesh): required input 'mesh'"),
                  StartsWith("14:14: node 'simplify' (decimate_mesh) has no parameter "
                             "'target_face'; did you mean 'target_faces'?"),
                  StartsWith("17:20: input 'mesh' of node 'measure' refers to unknown node "
                             "'simplyfy'; did you mean 'simplify'?"),
                  StartsWith("18:9: duplicate node id 'load' (first defined at 8:9)"),
                  StartsWith("22:11: node 'oops': unknown node type 'measure_meshes'"),
                  StartsWith("23:5: nodes[4]: unknown key 'extra'"),
                  StartsWith("25:11: output 'report' refers to 'measure.reports'")));
}

TEST(WorkflowLoaderTest, MissingFileAndFolderHaveNoPosition) {
  const NodeRegistry registry = test::make_test_registry();
  const LoadResult missing = load_workflow("/nonexistent/wf.yaml", registry);
  ASSERT_EQ(missing.diagnostics.size(), 1U);
  EXPECT_EQ(missing.diagnostics[0].text(), "/nonexistent/wf.yaml: no such file");
  const LoadResult folder = load_workflow(test::malformed_dir(), registry);
  ASSERT_EQ(folder.diagnostics.size(), 1U);
  EXPECT_THAT(folder.diagnostics[0].text(), HasSubstr("is a folder, not a workflow file"));
}

TEST(WorkflowLoaderTest, BinaryAndNonUtf8TextAreRejected) {
  const NodeRegistry registry = test::make_test_registry();
  const LoadResult binary =
      load_workflow_text(std::string("mmm_workflow: 1\nname: x\0y\n", 25), "b.yaml", registry);
  ASSERT_EQ(binary.diagnostics.size(), 1U);
  EXPECT_EQ(binary.diagnostics[0].text().substr(0, 14), "b.yaml:2:8: no");
  EXPECT_THAT(binary.diagnostics[0].message, HasSubstr("not a text file (NUL byte)"));
  const LoadResult latin1 = load_workflow_text("name: caf\xE9\n", "l.yaml", registry);
  ASSERT_EQ(latin1.diagnostics.size(), 1U);
  EXPECT_EQ(latin1.diagnostics[0].line, 1);
  EXPECT_EQ(latin1.diagnostics[0].column, 10);
  EXPECT_THAT(latin1.diagnostics[0].message, HasSubstr("not UTF-8 text"));
}

TEST(WorkflowLoaderTest, ExampleMeshDemoIsValid) {
  const NodeRegistry registry = test::make_test_registry();
  const LoadResult result = load_workflow(test::example_dir() / "mesh_demo.yaml", registry);
  ASSERT_TRUE(result.valid()) << result.diagnostics.front().text();
  const WorkflowDefinition& wf = result.definition;
  EXPECT_EQ(wf.name, "mesh_demo");
  EXPECT_EQ(wf.description, "Load, simplify and measure a surface");
  ASSERT_EQ(wf.inputs.size(), 1U);
  EXPECT_EQ(wf.inputs[0].type, PortType::kFile);
  EXPECT_EQ(wf.inputs[0].description, "The surface to process");
  ASSERT_EQ(wf.nodes.size(), 3U);
  const NodeInstance& simplify = wf.nodes[1];
  EXPECT_EQ(simplify.id, "simplify");
  EXPECT_EQ(simplify.type, "decimate_mesh");
  EXPECT_EQ(simplify.params.at("target_faces").value, ParamValue{std::int64_t{2000}});
  EXPECT_EQ(simplify.param_values().at("target_faces"), ParamValue{std::int64_t{2000}});
  const Reference& source = simplify.inputs.at("mesh").source;
  EXPECT_EQ(source.node, "load");
  EXPECT_EQ(source.port, "mesh");
  EXPECT_EQ(source.where.line, 20);
  EXPECT_EQ(source.where.column, 20);
  EXPECT_EQ(wf.nodes[0].params.at("format").value, ParamValue{std::string("stl")});
  EXPECT_TRUE(wf.nodes[0].inputs.at("file").source.is_study());
  ASSERT_EQ(wf.outputs.size(), 2U);
  EXPECT_EQ(wf.outputs[1].name, "report");
  EXPECT_EQ(wf.outputs[1].source.text(), "measure.report");
  EXPECT_EQ(wf.find_node("measure"), &wf.nodes[2]);
  EXPECT_EQ(wf.find_node("nope"), nullptr);
}

TEST(WorkflowLoaderTest, YamlScalarsBecomeTypedParameterValues) {
  const NodeRegistry registry = test::make_test_registry();
  const LoadResult result = load_workflow_text(R"(
mmm_workflow: 1
name: values
nodes:
  - id: n
    type: load_mesh
    params: {a: 12, b: 1.5, c: true, d: text, e: "12", f: 0x10, g: -3e2, h: yes}
)",
                                               "v.yaml", registry);
  const auto& p = result.definition.nodes.at(0).params;
  EXPECT_EQ(p.at("a").value, ParamValue{std::int64_t{12}});
  EXPECT_EQ(p.at("b").value, ParamValue{1.5});
  EXPECT_EQ(p.at("c").value, ParamValue{true});
  EXPECT_EQ(p.at("d").value, ParamValue{std::string("text")});
  EXPECT_EQ(p.at("e").value, ParamValue{std::string("12")});  // quoted: a string
  EXPECT_EQ(p.at("f").value, ParamValue{std::int64_t{16}});
  EXPECT_EQ(p.at("g").value, ParamValue{-300.0});
  EXPECT_EQ(p.at("h").value, ParamValue{std::string("yes")});  // YAML 1.2: not a boolean
}

TEST(WorkflowLoaderTest, CanonicalJsonAndHashIgnoreLayoutCommentsAndOrder) {
  const NodeRegistry registry = test::make_test_registry();
  const LoadResult block = load_workflow(test::example_dir() / "mesh_demo.yaml", registry);
  const LoadResult flow = load_workflow_text(R"(# the same workflow, written differently
name: mesh_demo
mmm_workflow: 1
outputs: {report: measure.report, coarse_surface: simplify.decimated}
nodes:
  - {type: measure_mesh, id: measure, inputs: {mesh: simplify.decimated}}
  - {id: load, type: load_mesh, params: {format: "stl"}, inputs: {file: study.surface}}
  - id: simplify   # comment
    inputs: {mesh: load.mesh}
    type: decimate_mesh
    params: {target_faces: 0x7D0}
description: "Load, simplify and measure a surface"
inputs: {surface: {description: The surface to process, type: File}}
)",
                                             "flow.yaml", registry);
  ASSERT_TRUE(block.valid());
  ASSERT_TRUE(flow.valid()) << flow.diagnostics.front().text();
  EXPECT_EQ(canonical_json(block.definition), canonical_json(flow.definition));
  const std::string hash = workflow_hash(block.definition);
  EXPECT_EQ(hash.size(), 64U);
  EXPECT_EQ(hash, workflow_hash(flow.definition));
  WorkflowDefinition changed = block.definition;
  changed.nodes[1].params.at("target_faces").value = std::int64_t{2001};
  EXPECT_NE(workflow_hash(changed), hash);
  EXPECT_EQ(canonical_json(block.definition)["nodes"][0]["id"], "load");  // sorted by id
}

TEST(WorkflowLoaderTest, SchemaComesFromOptionsOrMmmSchemaDir) {
  const NodeRegistry registry = test::make_test_registry();
  const mmm::test::ScratchDir dir("wf-schema");
  mmm::test::write_file(dir / "workflow.schema.yaml",
                        "{type: object, required: [title], properties: {title: {type: string}}}");
  const LoadResult custom = load_workflow(test::example_dir() / "mesh_demo.yaml", registry,
                                          {.schema_file = dir / "workflow.schema.yaml"});
  ASSERT_FALSE(custom.diagnostics.empty());
  EXPECT_EQ(custom.diagnostics[0].message, "top level: missing required key 'title'");

  ASSERT_EQ(setenv("MMM_SCHEMA_DIR", dir.path().c_str(), 1), 0);
  EXPECT_EQ(find_workflow_schema(), (dir / "workflow.schema.yaml").lexically_normal());
  ASSERT_EQ(setenv("MMM_SCHEMA_DIR", "/nonexistent", 1), 0);
  EXPECT_THAT([] { find_workflow_schema(); },
              ::testing::ThrowsMessage<IoError>(HasSubstr("MMM_SCHEMA_DIR")));
  ASSERT_EQ(unsetenv("MMM_SCHEMA_DIR"), 0);
  EXPECT_EQ(find_workflow_schema().filename(), "workflow.schema.yaml");
}

}  // namespace
}  // namespace mmm::workflow

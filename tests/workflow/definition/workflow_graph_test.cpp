#include "workflow/definition/workflow_graph.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/errors.h"
#include "tests/workflow/definition/test_node_types.h"
#include "workflow/definition/workflow_loader.h"

namespace mmm::workflow {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A definition with just ids and connections ("a <- b.mesh" style), no YAML.
WorkflowDefinition graph_of(
    const std::vector<std::pair<std::string, std::vector<std::string>>>& nodes) {
  WorkflowDefinition wf;
  wf.name = "g";
  for (const auto& [id, sources] : nodes) {
    NodeInstance node;
    node.id = id;
    node.type = "decimate_mesh";
    int port = 0;
    for (const std::string& source : sources) {
      node.inputs["in" + std::to_string(port++)] = {Reference{source, "decimated", {}}, {}};
    }
    wf.nodes.push_back(node);
  }
  return wf;
}

TEST(WorkflowGraphTest, TopologicalOrderPutsProducersFirstThenFileOrder) {
  // d takes from c and a; c from b; a and b have no inputs.
  const auto wf = graph_of({{"d", {"c", "a"}}, {"c", {"b"}}, {"a", {}}, {"b", {}}});
  EXPECT_THAT(topological_order(wf), ElementsAre("a", "b", "c", "d"));
  EXPECT_TRUE(find_cycles(wf).empty());
}

TEST(WorkflowGraphTest, TopologicalOrderOfTheExample) {
  const NodeRegistry registry = test::make_test_registry();
  const LoadResult result = load_workflow(test::example_dir() / "mesh_demo.yaml", registry);
  ASSERT_TRUE(result.valid());
  EXPECT_THAT(topological_order(result.definition), ElementsAre("load", "simplify", "measure"));
}

TEST(WorkflowGraphTest, EveryCycleIsNamedOnceFromItsFirstNode) {
  // Cycle x -> y -> x, a self-loop on s, and a three-cycle p -> q -> r -> p
  // with a chord; "free" depends on a cycle but is in none.
  const auto wf = graph_of({{"free", {"y"}},
                            {"x", {"y"}},
                            {"y", {"x"}},
                            {"s", {"s"}},
                            {"p", {"r"}},
                            {"q", {"p"}},
                            {"r", {"q", "p"}}});
  EXPECT_THAT(find_cycles(wf), ElementsAre(ElementsAre("x", "y", "x"), ElementsAre("s", "s"),
                                           ElementsAre("p", "r", "p")));
  EXPECT_THAT([&] { topological_order(wf); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("cycle x -> y -> x")));
}

TEST(WorkflowGraphTest, DotShowsInputsNodesOutputsAndTypedEdges) {
  const NodeRegistry registry = test::make_test_registry();
  const LoadResult result = load_workflow(test::example_dir() / "mesh_demo.yaml", registry);
  ASSERT_TRUE(result.valid());
  const std::string dot = workflow_to_dot(result.definition, registry);
  EXPECT_THAT(dot, ::testing::StartsWith("digraph \"mesh_demo\" {\n"));
  EXPECT_THAT(dot, HasSubstr("\"study.surface\" [shape=ellipse, label=\"surface\\nFile\"];"));
  EXPECT_THAT(dot, HasSubstr("\"load\" [shape=box, label=\"load\\nload_mesh\"];"));
  EXPECT_THAT(dot, HasSubstr("\"simplify\" [shape=box, label=\"simplify\\ndecimate_mesh\"];"));
  EXPECT_THAT(dot, HasSubstr("\"measure\" [shape=box, label=\"measure\\nmeasure_mesh\"];"));
  EXPECT_THAT(dot, HasSubstr("\"study.surface\" -> \"load\" [label=\"file\\nFile\"];"));
  EXPECT_THAT(dot, HasSubstr("\"load\" -> \"simplify\" [label=\"mesh -> mesh\\nMesh\"];"));
  EXPECT_THAT(dot, HasSubstr("\"simplify\" -> \"measure\" [label=\"decimated -> mesh\\nMesh\"];"));
  EXPECT_THAT(dot, HasSubstr("\"measure\" -> \"output.report\" [style=dashed, "
                             "label=\"report\\nReport\"];"));
  EXPECT_THAT(dot, ::testing::EndsWith("}\n"));
  // 3 connections + 2 exports.
  std::size_t edges = 0;
  for (std::size_t at = dot.find(" -> \""); at != std::string::npos;
       at = dot.find(" -> \"", at + 1)) {
    ++edges;
  }
  EXPECT_EQ(edges, 5U);
}

TEST(WorkflowGraphTest, DotHighlightsManualNodesAndMarksUnknownTypes) {
  const NodeRegistry registry = test::make_test_registry();
  const LoadResult result = load_workflow_text(R"(
mmm_workflow: 1
name: landmarks
inputs: {surface: {type: File}}
nodes:
  - {id: load, type: load_mesh, inputs: {file: study.surface}}
  - {id: pick, type: pick_landmarks, inputs: {mesh: load.mesh}}
  - {id: later, type: not_yet_written, inputs: {points: pick.landmarks}}
)",
                                               "l.yaml", registry);
  const std::string dot = workflow_to_dot(result.definition, registry);
  EXPECT_THAT(dot, HasSubstr("\"pick\" [shape=box, style=\"filled,bold\", fillcolor=\"#ffd966\", "
                             "label=\"pick\\npick_landmarks\\n(manual)\"];"));
  EXPECT_THAT(dot, HasSubstr("\"later\" [shape=box, style=dashed, "
                             "label=\"later\\nnot_yet_written (unknown type)\"];"));
  EXPECT_THAT(dot,
              HasSubstr("\"pick\" -> \"later\" [label=\"landmarks -> points\\nLandmarkSet\"]"));
}

}  // namespace
}  // namespace mmm::workflow

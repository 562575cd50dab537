// mmm validate|graph|nodes: the command-line face of workflow definitions.

#include <iostream>
#include <memory>
#include <string>

#include "app/commands/commands.h"
#include "workflow/definition/node_catalog.h"
#include "workflow/definition/workflow_graph.h"
#include "workflow/definition/workflow_loader.h"

namespace mmm::app {
namespace {

struct WorkflowArgs {
  std::string file;
};

// Prints the diagnostics to stderr; false when there were any.
bool report(const workflow::LoadResult& result, const std::string& file) {
  for (const workflow::Diagnostic& d : result.diagnostics) std::cerr << d.text() << '\n';
  if (result.valid()) return true;
  std::cerr << file << ": " << result.diagnostics.size() << " problem(s)\n";
  set_exit_code(1);
  return false;
}

void run_validate(const WorkflowArgs& args, const workflow::NodeRegistry& registry) {
  const workflow::LoadResult result = workflow::load_workflow(args.file, registry);
  if (!report(result, args.file)) return;
  std::cout << args.file << ": valid (" << result.definition.nodes.size() << " nodes)\n";
}

void run_graph(const WorkflowArgs& args, const workflow::NodeRegistry& registry) {
  const workflow::LoadResult result = workflow::load_workflow(args.file, registry);
  if (!report(result, args.file)) return;
  std::cout << workflow::workflow_to_dot(result.definition, registry);
}

void run_nodes(bool json, const workflow::NodeRegistry& registry) {
  if (json) {
    std::cout << workflow::registry_json(registry).dump(2) << '\n';
    return;
  }
  for (const workflow::NodeType* type : registry.all()) {
    std::cout << workflow::node_spec_text(type->spec) << '\n';
  }
  std::cout << "port types: " << workflow::port_type_names() << '\n';
  std::cout << "workflow file format: schemas/workflow.schema.yaml "
               "(examples in schemas/examples/)\n";
}

}  // namespace

void register_workflow_commands(CLI::App& app, const workflow::NodeRegistry& registry) {
  auto validate_args = std::make_shared<WorkflowArgs>();
  auto* validate = app.add_subcommand(
      "validate", "Check a workflow file: structure, node types, parameters and connections");
  validate->add_option("WORKFLOW", validate_args->file, "Workflow file (.yaml)")->required();
  validate->callback([validate_args, &registry] { run_validate(*validate_args, registry); });

  auto graph_args = std::make_shared<WorkflowArgs>();
  auto* graph = app.add_subcommand(
      "graph", "Print a workflow as a Graphviz graph (mmm graph WF.yaml | dot -Tsvg > wf.svg)");
  graph->add_option("WORKFLOW", graph_args->file, "Workflow file (.yaml)")->required();
  graph->callback([graph_args, &registry] { run_graph(*graph_args, registry); });

  auto nodes_json = std::make_shared<bool>(false);
  auto* nodes = app.add_subcommand(
      "nodes", "List the node types: ports, parameters with defaults, ranges and units");
  nodes->add_flag("--json", *nodes_json, "Print JSON instead of text");
  nodes->callback([nodes_json, &registry] { run_nodes(*nodes_json, registry); });
}

}  // namespace mmm::app

// Workflow YAML, validated against the schema and every node type.
#include <exception>

#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"
#include "nodes/registry.h"
#include "workflow/definition/workflow_loader.h"

namespace mmm::fuzz {

void workflow_yaml(const std::uint8_t* data, std::size_t size) {
  static const workflow::NodeRegistry registry = nodes::make_node_registry();
  try {
    (void)workflow::load_workflow_text(as_text(data, size), "input.yaml", registry);
  } catch (const std::exception&) {
  }
}

}  // namespace mmm::fuzz

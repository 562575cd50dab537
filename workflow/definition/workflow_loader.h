#pragma once
// Reading a workflow file: YAML -> structure check against
// schemas/workflow.schema.yaml -> WorkflowDefinition -> checks against the
// node types of a registry (workflow_validation.h). Every problem of every
// stage is collected as a located Diagnostic; nothing stops at the first.
//
//   const LoadResult result = load_workflow("mesh_demo.yaml", registry);
//   for (const Diagnostic& d : result.diagnostics) std::cerr << d.text() << '\n';
//   if (result.valid()) run(result.definition);
//
// Problems of the file itself (missing, a folder, binary, not UTF-8, empty,
// YAML syntax, more than one YAML document, top level not a mapping) are
// diagnostics too; only an unusable schema (an installation problem) throws.

#include <filesystem>
#include <string_view>
#include <vector>

#include "workflow/definition/diagnostic.h"
#include "workflow/definition/workflow_definition.h"
#include "workflow/node_registry.h"

namespace mmm::workflow {

struct LoadOptions {
  // The workflow schema; empty (default): find_workflow_schema().
  std::filesystem::path schema_file;
};

struct LoadResult {
  WorkflowDefinition definition;        // as much as could be read
  std::vector<Diagnostic> diagnostics;  // sorted by line, then column

  [[nodiscard]] bool valid() const { return diagnostics.empty(); }
};

// Where workflow.schema.yaml is, first match wins:
//   1. $MMM_SCHEMA_DIR/workflow.schema.yaml when the variable is set (it must
//      hold the file then);
//   2. <folder of the running executable>/../../schemas (build/bin/mmm in a
//      checkout);
//   3. the schemas/ folder of the source tree this library was compiled from.
// Throws IoError listing the places tried when none holds the file.
std::filesystem::path find_workflow_schema();

// Reads, checks and returns the workflow in `file`. Diagnostics name the file
// as given. Throws IoError only when the schema cannot be found or read.
LoadResult load_workflow(const std::filesystem::path& file, const NodeRegistry& registry,
                         const LoadOptions& options = {});

// Same for workflow text that is already in memory; `file` names it in
// diagnostics.
LoadResult load_workflow_text(std::string_view text, const std::filesystem::path& file,
                              const NodeRegistry& registry, const LoadOptions& options = {});

}  // namespace mmm::workflow

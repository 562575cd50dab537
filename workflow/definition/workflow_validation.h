#pragma once
// Checks of a workflow definition against the node types it uses, after its
// structure has passed the schema: node types exist, parameters exist and are
// well typed and in range, every required input is connected, connections
// refer to existing study inputs and node outputs of the right port type,
// node ids are unique (and not "study"), study input defaults fit their type,
// every study input is used, exported outputs exist, and the graph has no
// cycle. Every problem is reported, each at the line it concerns, with a hint
// where one helps (close names, the list of allowed ones).

#include <vector>

#include "workflow/definition/diagnostic.h"
#include "workflow/definition/workflow_definition.h"
#include "workflow/node_registry.h"

namespace mmm::workflow {

// Diagnostics in no particular order (the loader sorts them); empty when the
// definition is consistent. Elements the schema check already rejected (an
// empty id, a malformed reference) are skipped, not reported twice.
std::vector<Diagnostic> validate_workflow(const WorkflowDefinition& definition,
                                          const NodeRegistry& registry);

}  // namespace mmm::workflow

#pragma once
// The node graph of a workflow definition: connections run from the node
// that produces an output to the node whose input takes it. Order of
// execution, cycles, and a Graphviz picture.

#include <string>
#include <vector>

#include "workflow/definition/workflow_definition.h"
#include "workflow/node_registry.h"

namespace mmm::workflow {

// Every cycle of the graph, one per strongly connected component that has
// one, as node ids from a node back to it: {"a", "b", "c", "a"} (b takes an
// output of a, c one of b, a one of c). Each starts at the component's node
// that comes first in the file; the cycles come in that order too. Only
// connections between existing, uniquely identified nodes count.
std::vector<std::vector<std::string>> find_cycles(const WorkflowDefinition& definition);

// Node ids in an order in which every node comes after the nodes it takes
// outputs from; among nodes that are ready together, file order. Throws
// InvalidInputError naming a cycle when there is one.
std::vector<std::string> topological_order(const WorkflowDefinition& definition);

// Graphviz DOT text of the workflow, left to right: study inputs as ellipses
// ("study.NAME", label name and type), nodes as boxes labelled "id\ntype"
// (manual nodes filled yellow and marked "(manual)", unknown types dashed),
// exported outputs as notes ("output.NAME"), and one edge per connection
// labelled with the port names and the type it carries. Render it with
// `dot -Tsvg`.
std::string workflow_to_dot(const WorkflowDefinition& definition, const NodeRegistry& registry);

}  // namespace mmm::workflow

#pragma once
// The node types of the mmm executable.

#include "workflow/node_registry.h"

namespace mmm::nodes {

// A registry holding every node type of nodes/: load_mesh, decimate_mesh,
// measure_mesh.
workflow::NodeRegistry make_node_registry();

}  // namespace mmm::nodes

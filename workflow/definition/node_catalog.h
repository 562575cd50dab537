#pragma once
// A node type's spec as people and programs read it: what `mmm nodes` prints
// and what the golden tests of nodes/ pin, so a change of a port or a
// parameter shows up as a diff.

#include <nlohmann/json.hpp>
#include <string>

#include "workflow/node_registry.h"
#include "workflow/node_spec.h"

namespace mmm::workflow {

// {"name", "version", "description", "manual",
//  "inputs":  [{"name", "type", "required", "description"}],
//  "outputs": [{"name", "type", "description"}],
//  "params":  [{"name", "type", "default", "description", "unit"?, "min"?, "max"?,
//               "choices"?}]}
// Ports and parameters in declaration order; infinite range ends are left out.
nlohmann::json node_spec_json(const NodeSpec& spec);

// Several lines of text: name and version, description, then one line per
// input, output and parameter (type, required/default, range or choices,
// unit, description).
std::string node_spec_text(const NodeSpec& spec);

// {"node_types": [node_spec_json...] sorted by name,
//  "port_types": [{"name", "description"}], "schema": "schemas/workflow.schema.yaml"}
nlohmann::json registry_json(const NodeRegistry& registry);

}  // namespace mmm::workflow

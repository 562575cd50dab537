#pragma once
// A workflow as written in a workflow file (schemas/workflow.schema.yaml):
// study-level inputs, node instances with their parameters and connections,
// and the exported outputs. Every element remembers where it was written, so
// later checks can point at the line.
//
//   mmm_workflow: 1
//   name: mesh_demo
//   inputs:
//     surface: {type: File}
//   nodes:
//     - id: load
//       type: load_mesh
//       params: {format: stl}
//       inputs: {file: study.surface}
//   outputs:
//     mesh: load.mesh

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/definition/diagnostic.h"
#include "workflow/node_spec.h"
#include "workflow/port_type.h"

namespace mmm::workflow {

// The node id that names the study's inputs in references ("study.surface");
// no node may use it.
inline constexpr std::string_view kStudyNode = "study";

// "NODE.PORT" (an output of a node) or "study.NAME" (a study input).
struct Reference {
  std::string node;  // node id or "study"; empty when the text is not of the
                     // form NAME.NAME (already reported by the schema check)
  std::string port;  // output port, or study input name
  SourceLocation where;

  [[nodiscard]] bool is_study() const { return node == kStudyNode; }
  [[nodiscard]] bool well_formed() const { return !node.empty(); }
  // "node.port"
  [[nodiscard]] std::string text() const { return node + "." + port; }
};

struct StudyInput {
  std::string name;
  std::string type_name;         // as written
  std::optional<PortType> type;  // std::nullopt when type_name names no port type
  std::string description;
  std::optional<ParamValue> default_value;  // value types only (Number, Integer, String, Bool)
  SourceLocation where;                     // of the name
  SourceLocation type_where;
  SourceLocation default_where;
};

struct ParamSetting {
  ParamValue value;
  SourceLocation where;      // of the value
  SourceLocation key_where;  // of the parameter name
};

struct InputConnection {
  Reference source;
  SourceLocation key_where;  // of the input port name
};

struct NodeInstance {
  std::string id;
  std::string type;  // registered node type name
  std::string description;
  std::map<std::string, ParamSetting> params;     // name -> value as written
  std::map<std::string, InputConnection> inputs;  // input port -> source
  SourceLocation where;                           // of the node's mapping (its first key)
  SourceLocation id_where;
  SourceLocation type_where;

  // The parameter values as a NodeContext takes them (defaults not applied).
  [[nodiscard]] std::map<std::string, ParamValue> param_values() const;
};

struct WorkflowOutput {
  std::string name;  // export name
  Reference source;
  SourceLocation where;  // of the name
};

struct WorkflowDefinition {
  std::filesystem::path file;  // as given to the loader (for messages)
  int format_version = 1;
  std::string name;
  std::string description;
  std::vector<StudyInput> inputs;       // file order
  std::vector<NodeInstance> nodes;      // file order
  std::vector<WorkflowOutput> outputs;  // file order

  // nullptr when absent (the first one when an id is duplicated).
  [[nodiscard]] const NodeInstance* find_node(std::string_view id) const;
  [[nodiscard]] const StudyInput* find_input(std::string_view name) const;
};

// The definition as canonical JSON: everything it says (name, description,
// inputs with type/description/default, nodes sorted by id with type,
// description, params and inputs as "node.port" text, outputs), with keys
// sorted and no trace of the YAML layout, comments, key order or node order.
// Two files that define the same workflow give equal JSON.
nlohmann::json canonical_json(const WorkflowDefinition& definition);

// SHA-256 (64 lowercase hex) of canonical_json(definition).dump(): the
// workflow's content hash, recorded with every study made from it.
std::string workflow_hash(const WorkflowDefinition& definition);

}  // namespace mmm::workflow

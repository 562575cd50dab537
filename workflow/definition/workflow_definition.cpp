#include "workflow/definition/workflow_definition.h"

#include <algorithm>

#include "core/hash/sha256.h"
#include "workflow/definition/param_json.h"

namespace mmm::workflow {
namespace {

using detail::value_json;

template <class T>
const T* find_by(const std::vector<T>& items, std::string_view key, std::string T::*member) {
  const auto it =
      std::find_if(items.begin(), items.end(), [&](const T& item) { return item.*member == key; });
  return it == items.end() ? nullptr : &*it;
}

}  // namespace

std::map<std::string, ParamValue> NodeInstance::param_values() const {
  std::map<std::string, ParamValue> out;
  for (const auto& [name, setting] : params) out.emplace(name, setting.value);
  return out;
}

const NodeInstance* WorkflowDefinition::find_node(std::string_view id) const {
  return find_by(nodes, id, &NodeInstance::id);
}

const StudyInput* WorkflowDefinition::find_input(std::string_view input_name) const {
  return find_by(inputs, input_name, &StudyInput::name);
}

nlohmann::json canonical_json(const WorkflowDefinition& definition) {
  nlohmann::json out = nlohmann::json::object();
  out["mmm_workflow"] = definition.format_version;
  out["name"] = definition.name;
  out["description"] = definition.description;

  nlohmann::json inputs = nlohmann::json::object();
  for (const StudyInput& input : definition.inputs) {
    nlohmann::json entry = {{"type", input.type_name}, {"description", input.description}};
    if (input.default_value) entry["default"] = value_json(*input.default_value);
    inputs[input.name] = std::move(entry);
  }
  out["inputs"] = std::move(inputs);

  std::vector<const NodeInstance*> nodes;
  nodes.reserve(definition.nodes.size());
  for (const NodeInstance& node : definition.nodes) nodes.push_back(&node);
  std::stable_sort(nodes.begin(), nodes.end(),
                   [](const NodeInstance* a, const NodeInstance* b) { return a->id < b->id; });
  nlohmann::json node_list = nlohmann::json::array();
  for (const NodeInstance* node : nodes) {
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [name, setting] : node->params) params[name] = value_json(setting.value);
    nlohmann::json connections = nlohmann::json::object();
    for (const auto& [port, connection] : node->inputs) {
      connections[port] = connection.source.text();
    }
    node_list.push_back({{"id", node->id},
                         {"type", node->type},
                         {"description", node->description},
                         {"params", std::move(params)},
                         {"inputs", std::move(connections)}});
  }
  out["nodes"] = std::move(node_list);

  nlohmann::json outputs = nlohmann::json::object();
  for (const WorkflowOutput& output : definition.outputs) {
    outputs[output.name] = output.source.text();
  }
  out["outputs"] = std::move(outputs);
  return out;
}

std::string workflow_hash(const WorkflowDefinition& definition) {
  return hash::sha256_hex(canonical_json(definition).dump());
}

}  // namespace mmm::workflow

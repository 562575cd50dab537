#include "workflow/definition/workflow_validation.h"

#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "core/suggest.h"
#include "workflow/definition/workflow_graph.h"

namespace mmm::workflow {
namespace {

template <class T>
std::vector<std::string> names_of(const std::vector<T>& items) {
  std::vector<std::string> names;
  names.reserve(items.size());
  for (const T& item : items) names.push_back(item.name);
  return names;
}

std::string hint_list(std::string_view name, const std::vector<std::string>& known,
                      std::string_view what) {
  return did_you_mean(name, known) + " (" + std::string(what) + ": " + join_names(known) + ")";
}

std::string type_text(PortType type) { return std::string(port_type_name(type)); }

// Does a default value fit a value port type?
bool default_fits(PortType type, const ParamValue& value) {
  switch (type) {
    case PortType::kNumber: {
      const auto* d = std::get_if<double>(&value);
      return std::holds_alternative<std::int64_t>(value) || (d != nullptr && std::isfinite(*d));
    }
    case PortType::kInteger:
      return std::holds_alternative<std::int64_t>(value);
    case PortType::kString:
      return std::holds_alternative<std::string>(value);
    case PortType::kBool:
      return std::holds_alternative<bool>(value);
    default:
      return false;
  }
}

std::string typed_value_text(const ParamValue& value) {
  if (std::holds_alternative<std::string>(value)) return "string '" + param_value_text(value) + "'";
  if (std::holds_alternative<bool>(value)) return "boolean " + param_value_text(value);
  if (std::holds_alternative<std::int64_t>(value)) return "integer " + param_value_text(value);
  return "number " + param_value_text(value);
}

class Checker {
 public:
  Checker(const WorkflowDefinition& definition, const NodeRegistry& registry)
      : definition_(definition), registry_(registry) {
    for (const NodeInstance& node : definition_.nodes) {
      if (node.id.empty()) continue;
      if (first_by_id_.emplace(node.id, &node).second) node_ids_.push_back(node.id);
    }
  }

  std::vector<Diagnostic> run() {
    check_study_inputs();
    check_node_ids();
    for (const NodeInstance& node : definition_.nodes) check_node(node);
    check_outputs();
    check_unused_inputs();
    check_cycles();
    return std::move(diagnostics_);
  }

 private:
  void add(SourceLocation where, std::string message) {
    diagnostics_.push_back(
        {definition_.file.string(), where.line, where.column, std::move(message)});
  }

  [[nodiscard]] const NodeSpec* spec_of(const NodeInstance& node) const {
    const NodeType* type = registry_.find(node.type);
    return type == nullptr ? nullptr : &type->spec;
  }

  void check_study_inputs() {
    for (const StudyInput& input : definition_.inputs) {
      if (!input.type || !input.default_value) continue;
      if (!is_value_type(*input.type)) {
        add(input.default_where, "study input '" + input.name + "' of type " +
                                     type_text(*input.type) +
                                     " cannot have a default; only Number, Integer, String and "
                                     "Bool inputs take one (the file is given at study creation)");
      } else if (!default_fits(*input.type, *input.default_value)) {
        add(input.default_where, "default of study input '" + input.name + "' must be " +
                                     type_text(*input.type) + ", got " +
                                     typed_value_text(*input.default_value));
      }
    }
  }

  void check_node_ids() {
    std::map<std::string, const NodeInstance*> seen;
    for (const NodeInstance& node : definition_.nodes) {
      if (node.id.empty()) continue;
      if (node.id == kStudyNode) {
        add(node.id_where,
            "node id 'study' is reserved: 'study.NAME' refers to the study input "
            "NAME; choose another id");
      }
      const auto [it, inserted] = seen.emplace(node.id, &node);
      if (!inserted) {
        add(node.id_where, "duplicate node id '" + node.id + "' (first defined at " +
                               it->second->id_where.text() + "); node ids must be unique");
      }
    }
  }

  void check_node(const NodeInstance& node) {
    const NodeSpec* spec = spec_of(node);
    if (spec == nullptr && !node.type.empty()) {
      add(node.type_where, "node '" + node.id + "': unknown node type '" + node.type + "'" +
                               suggestion_for_type(node.type) +
                               " (run 'mmm nodes' to list the node types)");
    }
    if (spec != nullptr) check_params(node, *spec);
    if (spec != nullptr) check_ports(node, *spec);
    for (const auto& [port, connection] : node.inputs) {
      const PortSpec* input = spec == nullptr ? nullptr : spec->find_input(port);
      check_connection("input '" + port + "' of node '" + node.id + "'", connection.source,
                       input == nullptr ? std::nullopt : std::optional<PortType>(input->type));
    }
  }

  [[nodiscard]] std::string suggestion_for_type(const std::string& type) const {
    const std::vector<std::string> similar = registry_.similar_names(type);
    if (similar.empty()) return {};
    return "; did you mean " + join_names(similar) + "?";
  }

  void check_params(const NodeInstance& node, const NodeSpec& spec) {
    for (const auto& [name, setting] : node.params) {
      const ParamSpec* param = spec.find_param(name);
      if (param == nullptr) {
        add(setting.key_where, "node '" + node.id + "' (" + spec.name() + ") has no parameter '" +
                                   name + "'" +
                                   hint_list(name, names_of(spec.params()), "parameters"));
      } else if (const auto problem = param->check(setting.value)) {
        add(setting.where, "parameter '" + name + "' of node '" + node.id + "': " + *problem);
      }
    }
  }

  void check_ports(const NodeInstance& node, const NodeSpec& spec) {
    for (const auto& [port, connection] : node.inputs) {
      if (spec.find_input(port) == nullptr) {
        add(connection.key_where, "node '" + node.id + "' (" + spec.name() + ") has no input '" +
                                      port + "'" +
                                      hint_list(port, names_of(spec.inputs()), "inputs"));
      }
    }
    for (const PortSpec& input : spec.inputs()) {
      if (input.required && !node.inputs.contains(input.name)) {
        add(node.where, "node '" + node.id + "' (" + spec.name() + "): required input '" +
                            input.name + "' (" + type_text(input.type) +
                            ") is not connected; add it under 'inputs:' as " + input.name +
                            ": NODE.PORT or study.NAME");
      }
    }
  }

  // Checks that `source` exists and, when `expected` is known, that it
  // produces that type. `what` names the consumer ("input 'mesh' of node
  // 'simplify'"). Returns the produced type when known.
  std::optional<PortType> check_connection(const std::string& what, const Reference& source,
                                           std::optional<PortType> expected) {
    if (!source.well_formed()) return std::nullopt;
    std::optional<PortType> produced;
    if (source.is_study()) {
      const StudyInput* input = definition_.find_input(source.port);
      if (input == nullptr) {
        add(source.where, what + " refers to unknown study input '" + source.port + "'" +
                              hint_list(source.port, names_of(definition_.inputs), "study inputs"));
        return std::nullopt;
      }
      used_inputs_.insert(input->name);
      produced = input->type;
    } else {
      const auto it = first_by_id_.find(source.node);
      if (it == first_by_id_.end()) {
        add(source.where, what + " refers to unknown node '" + source.node + "'" +
                              hint_list(source.node, node_ids_, "nodes"));
        return std::nullopt;
      }
      const NodeSpec* spec = spec_of(*it->second);
      if (spec == nullptr) return std::nullopt;  // unknown type, reported at the node
      const PortSpec* output = spec->find_output(source.port);
      if (output == nullptr) {
        add(source.where, what + " refers to '" + source.text() + "', but node '" + source.node +
                              "' (" + spec->name() + ") has no output '" + source.port + "'" +
                              hint_list(source.port, names_of(spec->outputs()), "outputs"));
        return std::nullopt;
      }
      produced = output->type;
    }
    if (expected && produced && *expected != *produced) {
      add(source.where, what + " expects " + type_text(*expected) + ", got " +
                            type_text(*produced) + " from '" + source.text() + "'");
    }
    return produced;
  }

  void check_outputs() {
    for (const WorkflowOutput& output : definition_.outputs) {
      if (output.source.is_study()) {
        add(output.source.where, "output '" + output.name + "' refers to study input '" +
                                     output.source.port +
                                     "'; outputs export node results (NODE.PORT)");
        continue;
      }
      check_connection("output '" + output.name + "'", output.source, std::nullopt);
    }
  }

  void check_unused_inputs() {
    for (const StudyInput& input : definition_.inputs) {
      if (!used_inputs_.contains(input.name)) {
        add(input.where, "study input '" + input.name +
                             "' is not used by any node; connect it as 'study." + input.name +
                             "' or remove it");
      }
    }
  }

  void check_cycles() {
    for (const std::vector<std::string>& cycle : find_cycles(definition_)) {
      std::string text;
      for (const std::string& id : cycle) text += (text.empty() ? "" : " -> ") + id;
      const NodeInstance* first = definition_.find_node(cycle.front());
      add(first->id_where,
          "cycle: " + text + "; a node cannot depend, directly or not, on its own outputs");
    }
  }

  const WorkflowDefinition& definition_;
  const NodeRegistry& registry_;
  std::map<std::string, const NodeInstance*> first_by_id_;
  std::vector<std::string> node_ids_;  // file order, first occurrence
  std::set<std::string> used_inputs_;
  std::vector<Diagnostic> diagnostics_;
};

}  // namespace

std::vector<Diagnostic> validate_workflow(const WorkflowDefinition& definition,
                                          const NodeRegistry& registry) {
  return Checker(definition, registry).run();
}

}  // namespace mmm::workflow

#include "workflow/definition/node_catalog.h"

#include <array>
#include <charconv>
#include <cmath>
#include <sstream>

#include "workflow/definition/param_json.h"

namespace mmm::workflow {
namespace {

using detail::value_json;

// Shortest text that reads back as the same double: "1e-06", "0.1", "inf".
std::string shortest_text(double value) { return param_value_text(value); }

std::string value_text(const ParamValue& value) { return param_value_text(value); }

// A range as text for people: "[4, inf]", "[1, 180]"; empty when unbounded.
std::string range_text(const ParamRange& range) {
  if (std::isinf(range.min) && std::isinf(range.max)) return {};
  return "[" + shortest_text(range.min) + ", " + shortest_text(range.max) + "]";
}

// A range end in JSON: an integer for integer parameters.
nlohmann::json bound_json(double bound, ParamType type) {
  if (type == ParamType::kInteger) return static_cast<std::int64_t>(bound);
  return bound;
}

std::string padded(const std::string& text, std::size_t width) {
  return text.size() >= width ? text + " " : text + std::string(width - text.size(), ' ');
}

}  // namespace

nlohmann::json node_spec_json(const NodeSpec& spec) {
  nlohmann::json out;
  out["name"] = spec.name();
  out["version"] = spec.version();
  out["description"] = spec.description();
  out["manual"] = spec.is_manual();
  out["inputs"] = nlohmann::json::array();
  for (const PortSpec& port : spec.inputs()) {
    out["inputs"].push_back({{"name", port.name},
                             {"type", port_type_name(port.type)},
                             {"required", port.required},
                             {"description", port.description}});
  }
  out["outputs"] = nlohmann::json::array();
  for (const PortSpec& port : spec.outputs()) {
    out["outputs"].push_back({{"name", port.name},
                              {"type", port_type_name(port.type)},
                              {"description", port.description}});
  }
  out["params"] = nlohmann::json::array();
  for (const ParamSpec& param : spec.params()) {
    nlohmann::json entry = {{"name", param.name},
                            {"type", param_type_name(param.type)},
                            {"default", value_json(param.default_value)},
                            {"description", param.description}};
    if (!param.unit.empty()) entry["unit"] = param.unit;
    if (param.type == ParamType::kNumber || param.type == ParamType::kInteger) {
      if (std::isfinite(param.range.min)) entry["min"] = bound_json(param.range.min, param.type);
      if (std::isfinite(param.range.max)) entry["max"] = bound_json(param.range.max, param.type);
    }
    if (param.type == ParamType::kEnum) entry["choices"] = param.choices;
    out["params"].push_back(std::move(entry));
  }
  return out;
}

std::string node_spec_text(const NodeSpec& spec) {
  constexpr std::size_t kNameWidth = 22;
  constexpr std::size_t kTypeWidth = 10;
  std::ostringstream out;
  out << spec.name() << " (version " << spec.version() << (spec.is_manual() ? ", manual" : "")
      << ")\n";
  out << "  " << spec.description() << '\n';
  if (!spec.inputs().empty()) out << "  inputs:\n";
  for (const PortSpec& port : spec.inputs()) {
    out << "    " << padded(port.name, kNameWidth)
        << padded(std::string(port_type_name(port.type)), kTypeWidth)
        << padded(port.required ? "required" : "optional", kTypeWidth) << port.description << '\n';
  }
  if (!spec.outputs().empty()) out << "  outputs:\n";
  for (const PortSpec& port : spec.outputs()) {
    out << "    " << padded(port.name, kNameWidth)
        << padded(std::string(port_type_name(port.type)), kTypeWidth) << port.description << '\n';
  }
  if (!spec.params().empty()) out << "  params:\n";
  for (const ParamSpec& param : spec.params()) {
    std::string details = "default " + value_text(param.default_value);
    if (!param.unit.empty()) details += " " + param.unit;
    if (param.type == ParamType::kNumber || param.type == ParamType::kInteger) {
      const std::string range = range_text(param.range);
      if (!range.empty()) details += ", range " + range;
    }
    if (param.type == ParamType::kEnum) {
      std::string choices;
      for (const std::string& choice : param.choices) {
        choices += (choices.empty() ? "" : ", ") + choice;
      }
      details += ", one of {" + choices + "}";
    }
    out << "    " << padded(param.name, kNameWidth)
        << padded(std::string(param_type_name(param.type)), kTypeWidth) << param.description << " ("
        << details << ")\n";
  }
  return out.str();
}

nlohmann::json registry_json(const NodeRegistry& registry) {
  nlohmann::json out;
  out["node_types"] = nlohmann::json::array();
  for (const NodeType* type : registry.all())
    out["node_types"].push_back(node_spec_json(type->spec));
  out["port_types"] = nlohmann::json::array();
  for (const PortTypeInfo& info : all_port_types()) {
    out["port_types"].push_back({{"name", info.name}, {"description", info.description}});
  }
  out["schema"] = "schemas/workflow.schema.yaml";
  return out;
}

}  // namespace mmm::workflow

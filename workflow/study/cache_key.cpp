#include "workflow/study/cache_key.h"

#include "core/errors.h"
#include "core/hash/sha256.h"

namespace mmm::workflow {
namespace {

std::string short_hash(const std::string& hash) { return hash.substr(0, 12); }

}  // namespace

std::map<std::string, ParamValue> effective_params(const NodeSpec& spec,
                                                   const std::map<std::string, ParamValue>& given) {
  for (const auto& [name, value] : given) {
    const ParamSpec* param = spec.find_param(name);
    if (param == nullptr) {
      throw InvalidInputError("node type " + spec.name() + " has no parameter '" + name + "'");
    }
    if (const auto problem = param->check(value)) {
      throw InvalidInputError("parameter '" + name + "' of node type " + spec.name() + " " +
                              *problem);
    }
  }
  std::map<std::string, ParamValue> out;
  for (const ParamSpec& param : spec.params()) {
    const auto it = given.find(param.name);
    ParamValue value = it != given.end() ? it->second : param.default_value;
    if (param.type == ParamType::kNumber) {
      if (const auto* integer = std::get_if<std::int64_t>(&value)) {
        value = static_cast<double>(*integer);
      }
    }
    out.emplace(param.name, std::move(value));
  }
  return out;
}

nlohmann::json param_value_json(const ParamValue& value) {
  struct Visitor {
    nlohmann::json operator()(double v) const { return {{"number", v}}; }
    nlohmann::json operator()(std::int64_t v) const { return {{"integer", v}}; }
    nlohmann::json operator()(const std::string& v) const { return {{"string", v}}; }
    nlohmann::json operator()(bool v) const { return {{"bool", v}}; }
  };
  return std::visit(Visitor{}, value);
}

ParamValue param_value_from_json(const nlohmann::json& json) {
  if (json.contains("number")) return json["number"].get<double>();
  if (json.contains("integer")) return json["integer"].get<std::int64_t>();
  if (json.contains("string")) return json["string"].get<std::string>();
  if (json.contains("bool")) return json["bool"].get<bool>();
  throw InvalidInputError("not a parameter value: " + json.dump());
}

nlohmann::json cache_key_json(const CacheKeyParts& parts) {
  nlohmann::json params = nlohmann::json::object();
  for (const auto& [name, value] : parts.params) params[name] = param_value_json(value);
  nlohmann::json inputs = nlohmann::json::object();
  for (const auto& [port, hash] : parts.input_hashes) inputs[port] = hash;
  return {{"type", parts.node_type},
          {"version", parts.version},
          {"params", params},
          {"inputs", inputs}};
}

CacheKeyParts cache_key_parts_from_json(const nlohmann::json& json) {
  CacheKeyParts parts;
  parts.node_type = json.at("type").get<std::string>();
  parts.version = json.at("version").get<int>();
  for (const auto& [name, value] : json.at("params").items()) {
    parts.params.emplace(name, param_value_from_json(value));
  }
  for (const auto& [port, hash] : json.at("inputs").items()) {
    parts.input_hashes.emplace(port, hash.get<std::string>());
  }
  return parts;
}

std::string cache_key(const CacheKeyParts& parts) {
  return hash::sha256_hex(cache_key_json(parts).dump());
}

std::vector<std::string> describe_key_changes(const CacheKeyParts& before,
                                              const CacheKeyParts& now) {
  std::vector<std::string> changes;
  if (before.node_type != now.node_type) {
    changes.push_back("node type changed from " + before.node_type + " to " + now.node_type);
  }
  if (before.version != now.version) {
    changes.push_back("implementation version changed from " + std::to_string(before.version) +
                      " to " + std::to_string(now.version));
  }
  for (const auto& [name, value] : now.params) {
    const auto it = before.params.find(name);
    if (it == before.params.end()) {
      changes.push_back("parameter '" + name + "' is new (" + param_value_text(value) + ")");
    } else if (it->second != value) {
      changes.push_back("parameter '" + name + "' changed from " + param_value_text(it->second) +
                        " to " + param_value_text(value));
    }
  }
  for (const auto& [name, value] : before.params) {
    if (!now.params.contains(name)) changes.push_back("parameter '" + name + "' was removed");
  }
  for (const auto& [port, hash] : now.input_hashes) {
    const auto it = before.input_hashes.find(port);
    if (it == before.input_hashes.end()) {
      changes.push_back("input '" + port + "' is newly connected (" + short_hash(hash) + ")");
    } else if (it->second != hash) {
      changes.push_back("input '" + port + "' changed content (" + short_hash(it->second) + " -> " +
                        short_hash(hash) + ")");
    }
  }
  for (const auto& [port, hash] : before.input_hashes) {
    if (!now.input_hashes.contains(port)) {
      changes.push_back("input '" + port + "' is no longer connected");
    }
  }
  return changes;
}

}  // namespace mmm::workflow

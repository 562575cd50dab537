#include "workflow/run/node_request.h"

#include <nlohmann/json.hpp>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "workflow/host_and_time.h"
#include "workflow/study/cache_key.h"

namespace mmm::workflow {

namespace fs = std::filesystem;
using RequestJson = nlohmann::json;

namespace {

constexpr const char* kRequestFormat = "mmm-node-request";
constexpr const char* kResultFormat = "mmm-node-result";
constexpr std::size_t kMaxRequestBytes = std::size_t{16} << 20U;

RequestJson parse_document(std::string_view text, const fs::path& source, const char* format) {
  RequestJson root;
  try {
    root = parse_json(text, JsonLimits{kMaxRequestBytes, 16});
  } catch (const RequestJson::parse_error& error) {
    throw IoError(source, std::string("is not JSON: ") + error.what());
  }
  if (!root.is_object() || root.value("format", "") != format || root.value("version", 0) != 1) {
    throw IoError(source, std::string("is not an ") + format + " document, version 1");
  }
  return root;
}

const RequestJson& field(const RequestJson& root, const char* key, const fs::path& source) {
  const auto it = root.find(key);
  if (it == root.end()) throw IoError(source, std::string("field '") + key + "' is missing");
  return *it;
}

std::string text_field(const RequestJson& root, const char* key, const fs::path& source) {
  const RequestJson& value = field(root, key, source);
  if (!value.is_string())
    throw IoError(source, std::string("field '") + key + "' must be a string");
  return value.get<std::string>();
}

fs::path absolute_field(const RequestJson& root, const char* key, const fs::path& source) {
  fs::path path = text_field(root, key, source);
  if (!path.is_absolute()) {
    throw IoError(source, std::string("field '") + key + "' must be an absolute path");
  }
  return path;
}

std::pair<PortType, std::string> typed_hash(const RequestJson& value, const std::string& where,
                                            const fs::path& source) {
  if (!value.is_object()) throw IoError(source, where + " must be an object {type, hash}");
  const std::optional<PortType> type = port_type_from_name(value.value("type", ""));
  const std::string hash = value.value("hash", "");
  if (!type) throw IoError(source, where + ": unknown type '" + value.value("type", "") + "'");
  if (!ArtifactStore::is_valid_hash(hash))
    throw IoError(source, where + ": 'hash' is not a SHA-256");
  return {*type, hash};
}

}  // namespace

std::string node_request_text(const NodeRequest& request) {
  RequestJson root;
  root["format"] = kRequestFormat;
  root["version"] = 1;
  root["node"] = request.job.node;
  root["node_type"] = request.job.type->spec.name();
  root["execution_id"] = request.job.execution_id;
  root["cache_key"] = request.job.cache_key;
  RequestJson inputs = RequestJson::object();
  for (const auto& [port, ref] : request.job.inputs) {
    inputs[port] = {{"type", port_type_name(ref.type)}, {"hash", ref.hash}};
  }
  root["inputs"] = std::move(inputs);
  RequestJson params = RequestJson::object();
  for (const auto& [name, value] : request.job.params) params[name] = param_value_json(value);
  root["params"] = std::move(params);
  root["artifacts"] = request.artifacts.string();
  if (request.pool) root["pool"] = request.pool->string();
  root["scratch"] = request.scratch.string();
  root["result"] = request.result.string();
  return root.dump(2);
}

NodeRequest node_request_from_text(std::string_view text, const fs::path& source,
                                   const NodeRegistry& registry) {
  const RequestJson root = parse_document(text, source, kRequestFormat);
  NodeRequest request;
  request.job.node = text_field(root, "node", source);
  const std::string type_name = text_field(root, "node_type", source);
  request.job.type = registry.find(type_name);
  if (request.job.type == nullptr) {
    throw IoError(source, "node type '" + type_name +
                              "' is not known to this mmm; hint: the workers must run the same "
                              "mmm version as the coordinator");
  }
  const RequestJson& id = field(root, "execution_id", source);
  if (!id.is_number_integer()) throw IoError(source, "field 'execution_id' must be an integer");
  request.job.execution_id = id.get<std::int64_t>();
  request.job.cache_key = text_field(root, "cache_key", source);
  request.artifacts = absolute_field(root, "artifacts", source);
  if (root.contains("pool")) request.pool = absolute_field(root, "pool", source);
  request.scratch = absolute_field(root, "scratch", source);
  request.result = absolute_field(root, "result", source);
  const RequestJson& inputs = field(root, "inputs", source);
  if (!inputs.is_object()) throw IoError(source, "field 'inputs' must be an object");
  for (const auto& [port, value] : inputs.items()) {
    const auto [type, hash] = typed_hash(value, "input '" + port + "'", source);
    request.job.inputs[port] = {type, hash,
                                request.artifacts / ArtifactStore::relative_path_of(hash)};
  }
  const RequestJson& params = field(root, "params", source);
  if (!params.is_object()) throw IoError(source, "field 'params' must be an object");
  for (const auto& [name, value] : params.items()) {
    try {
      request.job.params[name] = param_value_from_json(value);
    } catch (const std::exception& error) {
      throw IoError(source, "parameter '" + name + "': " + error.what());
    }
  }
  return request;
}

std::string completion_text(const Completion& completion, const std::string& host) {
  RequestJson root;
  root["format"] = kResultFormat;
  root["version"] = 1;
  root["node"] = completion.node;
  root["execution_id"] = completion.execution_id;
  RequestJson outputs = RequestJson::object();
  for (const auto& [port, output] : completion.outputs) {
    outputs[port] = {{"type", port_type_name(output.type)}, {"hash", output.hash}};
  }
  root["outputs"] = std::move(outputs);
  root["error"] = completion.error;
  RequestJson logs = RequestJson::array();
  for (const LogLine& line : completion.logs) {
    logs.push_back(
        {{"time", line.time}, {"level", log_level_name(line.level)}, {"message", line.message}});
  }
  root["logs"] = std::move(logs);
  root["seconds"] = completion.seconds;
  root["host"] = host;
  return root.dump(2);
}

Completion completion_from_text(std::string_view text, const fs::path& source) {
  const RequestJson root = parse_document(text, source, kResultFormat);
  Completion completion;
  completion.node = text_field(root, "node", source);
  const RequestJson& id = field(root, "execution_id", source);
  if (!id.is_number_integer()) throw IoError(source, "field 'execution_id' must be an integer");
  completion.execution_id = id.get<std::int64_t>();
  const RequestJson& outputs = field(root, "outputs", source);
  if (!outputs.is_object()) throw IoError(source, "field 'outputs' must be an object");
  for (const auto& [port, value] : outputs.items()) {
    const auto [type, hash] = typed_hash(value, "output '" + port + "'", source);
    completion.outputs[port] = {type, hash};
  }
  completion.error = text_field(root, "error", source);
  const RequestJson& logs = field(root, "logs", source);
  if (!logs.is_array()) throw IoError(source, "field 'logs' must be an array");
  for (const RequestJson& line : logs) {
    if (!line.is_object()) throw IoError(source, "a log line must be an object");
    completion.logs.push_back({line.value("time", ""), log_level_from_name(line.value("level", "")),
                               line.value("message", "")});
  }
  const RequestJson& seconds = field(root, "seconds", source);
  if (!seconds.is_number()) throw IoError(source, "field 'seconds' must be a number");
  completion.seconds = seconds.get<double>();
  return completion;
}

Completion run_node_request(const NodeRequest& request) {
  ArtifactStore artifacts(request.artifacts);
  if (request.pool) artifacts.share_with(*request.pool);
  fs::create_directories(request.scratch);
  Completion completion =
      execute(request.job, artifacts, request.scratch, request.scratch / "crash-marker", nullptr);
  write_file_atomically(request.result, completion_text(completion, host_name()), "a node result");
  return completion;
}

}  // namespace mmm::workflow

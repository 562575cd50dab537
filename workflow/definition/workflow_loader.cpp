#include "workflow/definition/workflow_loader.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <system_error>
#include <utility>

#include "core/bounded_yaml.h"
#include "core/errors.h"
#include "core/suggest.h"
#include "workflow/definition/workflow_validation.h"
#include "workflow/definition/yaml_scalar.h"
#include "workflow/definition/yaml_schema.h"

namespace mmm::workflow {
namespace {

constexpr const char* kSchemaFileName = "workflow.schema.yaml";
constexpr const char* kExpectedStart =
    "a workflow file is a YAML mapping that starts with 'mmm_workflow: 1' (see "
    "schemas/workflow.schema.yaml and schemas/examples/)";

class Collector {
 public:
  explicit Collector(std::string file) : file_(std::move(file)) {}

  void add(SourceLocation where, std::string message) {
    diagnostics_.push_back({file_, where.line, where.column, std::move(message)});
  }
  std::vector<Diagnostic>& diagnostics() { return diagnostics_; }

 private:
  std::string file_;
  std::vector<Diagnostic> diagnostics_;
};

// 1-based line and column of a byte offset (columns count bytes).
SourceLocation location_of_offset(std::string_view text, std::size_t offset) {
  SourceLocation where{1, 1};
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++where.line;
      where.column = 1;
    } else {
      ++where.column;
    }
  }
  return where;
}

// Offset of the first byte that does not belong to a well-formed UTF-8
// sequence, or std::nullopt.
std::optional<std::size_t> invalid_utf8_offset(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto lead = static_cast<unsigned char>(text[i]);
    std::size_t length = 0;
    if (lead < 0x80U) {
      length = 1;
    } else if ((lead & 0xE0U) == 0xC0U && lead >= 0xC2U) {
      length = 2;
    } else if ((lead & 0xF0U) == 0xE0U) {
      length = 3;
    } else if ((lead & 0xF8U) == 0xF0U && lead <= 0xF4U) {
      length = 4;
    } else {
      return i;
    }
    if (i + length > text.size()) return i;
    for (std::size_t k = 1; k < length; ++k) {
      if ((static_cast<unsigned char>(text[i + k]) & 0xC0U) != 0x80U) return i;
    }
    i += length;
  }
  return std::nullopt;
}

// "a.b" -> {a, b}; anything else -> {"", text} (the schema check reports it).
Reference parse_reference(const YAML::Node& node) {
  Reference ref;
  ref.where = location_of(node);
  if (yaml_kind(node) != YamlKind::kString) return ref;
  const std::string& text = node.Scalar();
  const std::size_t dot = text.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == text.size() ||
      text.find('.', dot + 1) != std::string::npos) {
    ref.port = text;
    return ref;
  }
  ref.node = text.substr(0, dot);
  ref.port = text.substr(dot + 1);
  return ref;
}

// Node::IsMap() and friends throw on the placeholder an absent key returns.
bool is_map(const YAML::Node& node) { return node.IsDefined() && node.IsMap(); }
bool is_sequence(const YAML::Node& node) { return node.IsDefined() && node.IsSequence(); }

std::string string_or_empty(const YAML::Node& node) {
  return yaml_kind(node) == YamlKind::kString ? node.Scalar() : std::string();
}

// Reports keys that appear twice in a mapping anywhere in the document,
// except in the `inputs` of a node, which read_node reports with a message of
// its own.
void report_duplicate_keys(const YAML::Node& node, const std::vector<std::string>& path,
                           Collector& out) {
  const bool node_inputs = path.size() == 3 && path[0] == "nodes" && path[2] == "inputs";
  if (node.IsMap()) {
    std::map<std::string, SourceLocation> seen;
    for (const auto& entry : node) {
      if (!entry.first.IsScalar()) continue;
      const std::string& key = entry.first.Scalar();
      const auto [it, inserted] = seen.emplace(key, location_of(entry.first));
      if (!inserted && !node_inputs) {
        out.add(location_of(entry.first), "duplicate key '" + key + "' (first at " +
                                              it->second.text() +
                                              "); a YAML mapping holds each key once");
      }
      std::vector<std::string> child = path;
      child.push_back(key);
      report_duplicate_keys(entry.second, child, out);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      std::vector<std::string> child = path;
      child.push_back(std::to_string(i));
      report_duplicate_keys(node[i], child, out);
    }
  }
}

StudyInput read_study_input(const std::string& name, const YAML::Node& key, const YAML::Node& value,
                            Collector& out) {
  StudyInput input;
  input.name = name;
  input.where = location_of(key);
  if (!is_map(value)) return input;
  const YAML::Node type = value["type"];
  input.type_name = string_or_empty(type);
  input.type_where = location_of(type);
  if (!input.type_name.empty()) {
    input.type = port_type_from_name(input.type_name);
    if (!input.type) {
      std::vector<std::string> names;
      for (const PortTypeInfo& info : all_port_types()) names.emplace_back(info.name);
      out.add(input.type_where, "study input '" + name + "': unknown port type '" +
                                    input.type_name + "'" + did_you_mean(input.type_name, names) +
                                    " (port types: " + port_type_names() + ")");
    }
  }
  input.description = string_or_empty(value["description"]);
  const YAML::Node default_value = value["default"];
  if (default_value.IsDefined()) {
    input.default_value = yaml_param_value(default_value);
    input.default_where = default_value.IsNull() ? input.where : location_of(default_value);
  }
  return input;
}

NodeInstance read_node(const YAML::Node& item, Collector& out) {
  NodeInstance node;
  node.where = location_of(item);
  if (!is_map(item)) return node;
  const YAML::Node id = item["id"];
  node.id = string_or_empty(id);
  node.id_where = location_of(id);
  const YAML::Node type = item["type"];
  node.type = string_or_empty(type);
  node.type_where = location_of(type);
  node.description = string_or_empty(item["description"]);
  const YAML::Node params = item["params"];
  if (is_map(params)) {
    for (const auto& entry : params) {
      const auto value = yaml_param_value(entry.second);
      if (!entry.first.IsScalar() || !value) continue;  // the schema check reported it
      node.params.emplace(entry.first.Scalar(), ParamSetting{*value, location_of(entry.second),
                                                             location_of(entry.first)});
    }
  }
  const YAML::Node inputs = item["inputs"];
  if (is_map(inputs)) {
    for (const auto& entry : inputs) {
      if (!entry.first.IsScalar()) continue;
      const std::string& port = entry.first.Scalar();
      InputConnection connection{parse_reference(entry.second), location_of(entry.first)};
      const auto [it, inserted] = node.inputs.emplace(port, connection);
      if (!inserted) {
        out.add(connection.key_where,
                "input '" + port + "' of node '" + node.id + "' is connected twice (first to '" +
                    it->second.source.text() + "' at " + it->second.key_where.text() +
                    "); an input takes exactly one connection");
      }
    }
  }
  return node;
}

WorkflowDefinition read_definition(const YAML::Node& root, const std::filesystem::path& file,
                                   Collector& out) {
  WorkflowDefinition definition;
  definition.file = file;
  if (const auto version = yaml_param_value(root["mmm_workflow"])) {
    if (const auto* v = std::get_if<std::int64_t>(&*version)) {
      definition.format_version = static_cast<int>(*v);
    }
  }
  definition.name = string_or_empty(root["name"]);
  definition.description = string_or_empty(root["description"]);
  const YAML::Node inputs = root["inputs"];
  if (is_map(inputs)) {
    for (const auto& entry : inputs) {
      if (!entry.first.IsScalar()) continue;
      const std::string& name = entry.first.Scalar();
      if (definition.find_input(name) != nullptr) continue;  // duplicate key, reported
      definition.inputs.push_back(read_study_input(name, entry.first, entry.second, out));
    }
  }
  const YAML::Node nodes = root["nodes"];
  if (is_sequence(nodes)) {
    for (const auto& item : nodes) definition.nodes.push_back(read_node(item, out));
  }
  const YAML::Node outputs = root["outputs"];
  if (is_map(outputs)) {
    for (const auto& entry : outputs) {
      if (!entry.first.IsScalar()) continue;
      const std::string& name = entry.first.Scalar();
      const bool duplicate =
          std::any_of(definition.outputs.begin(), definition.outputs.end(),
                      [&](const WorkflowOutput& output) { return output.name == name; });
      if (duplicate) continue;  // reported as a duplicate key
      definition.outputs.push_back({name, parse_reference(entry.second), location_of(entry.first)});
    }
  }
  return definition;
}

// Parses the text into its YAML documents; reports and returns std::nullopt
// when the file is not one YAML mapping.
std::optional<YAML::Node> parse_document(std::string_view text, Collector& out) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    out.add({1, 1}, std::string("the file is empty; ") + kExpectedStart);
    return std::nullopt;
  }
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    out.add(location_of_offset(text, nul),
            std::string("not a text file (NUL byte); ") + kExpectedStart);
    return std::nullopt;
  }
  if (const auto bad = invalid_utf8_offset(text)) {
    out.add(location_of_offset(text, *bad),
            std::string("not UTF-8 text (invalid byte sequence); ") + kExpectedStart);
    return std::nullopt;
  }
  std::vector<YAML::Node> documents;
  try {
    documents = load_all_yaml(text);
  } catch (const YAML::Exception& e) {
    const SourceLocation where = e.mark.is_null()
                                     ? SourceLocation{1, 1}
                                     : SourceLocation{e.mark.line + 1, e.mark.column + 1};
    out.add(where, "YAML syntax error: " + e.msg);
    return std::nullopt;
  }
  if (documents.empty()) {
    out.add({1, 1}, std::string("the file holds only comments; ") + kExpectedStart);
    return std::nullopt;
  }
  if (documents.size() > 1) {
    out.add(location_of(documents[1]),
            "the file holds " + std::to_string(documents.size()) +
                " YAML documents; a workflow file holds exactly one (remove the '---' "
                "separators)");
    return std::nullopt;
  }
  const YAML::Node& root = documents.front();
  if (!root.IsMap()) {
    const SourceLocation where = location_of(root);
    out.add(where.known() ? where : SourceLocation{1, 1}, "not a workflow file: the top level is " +
                                                              yaml_value_description(root) + "; " +
                                                              kExpectedStart);
    return std::nullopt;
  }
  return root;
}

std::optional<std::filesystem::path> existing_schema_in(const std::filesystem::path& folder) {
  std::error_code error;
  const std::filesystem::path file = folder / kSchemaFileName;
  if (std::filesystem::is_regular_file(file, error)) return file.lexically_normal();
  return std::nullopt;
}

}  // namespace

std::filesystem::path find_workflow_schema() {
  if (const char* dir = std::getenv("MMM_SCHEMA_DIR"); dir != nullptr && *dir != '\0') {
    if (auto file = existing_schema_in(dir)) return *file;
    throw IoError(std::filesystem::path(dir) / kSchemaFileName,
                  "no workflow schema here (MMM_SCHEMA_DIR is set to this folder)");
  }
  std::vector<std::filesystem::path> tried;
  std::error_code error;
  const std::filesystem::path executable = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path folder = executable.parent_path() / ".." / ".." / "schemas";
    if (auto file = existing_schema_in(folder)) return *file;
    tried.push_back(folder);
  }
  // This file is workflow/definition/workflow_loader.cpp in the source tree.
  const std::filesystem::path source_folder =
      std::filesystem::path(__FILE__).parent_path() / ".." / ".." / "schemas";
  if (auto file = existing_schema_in(source_folder)) return *file;
  tried.push_back(source_folder);
  std::string places;
  for (const auto& folder : tried) places += " " + folder.lexically_normal().string();
  throw IoError(kSchemaFileName, "workflow schema not found (looked in" + places +
                                     "); set MMM_SCHEMA_DIR to the folder that holds it");
}

LoadResult load_workflow(const std::filesystem::path& file, const NodeRegistry& registry,
                         const LoadOptions& options) {
  std::error_code error;
  const auto status = std::filesystem::status(file, error);
  std::string problem;
  if (!std::filesystem::exists(status)) {
    problem = "no such file";
  } else if (std::filesystem::is_directory(status)) {
    problem = "is a folder, not a workflow file";
  }
  std::string text;
  if (problem.empty()) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      problem = "cannot be read (permissions?)";
    } else {
      text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
  }
  if (!problem.empty()) {
    LoadResult result;
    result.definition.file = file;
    result.diagnostics.push_back({file.string(), 0, 0, problem});
    return result;
  }
  return load_workflow_text(text, file, registry, options);
}

LoadResult load_workflow_text(std::string_view text, const std::filesystem::path& file,
                              const NodeRegistry& registry, const LoadOptions& options) {
  const YamlSchema schema = YamlSchema::from_file(
      options.schema_file.empty() ? find_workflow_schema() : options.schema_file);
  Collector out(file.string());
  LoadResult result;
  result.definition.file = file;
  const std::optional<YAML::Node> root = parse_document(text, out);
  if (root) {
    for (const SchemaViolation& violation : schema.validate(*root)) {
      out.add(violation.where, violation.text());
    }
    report_duplicate_keys(*root, {}, out);
    result.definition = read_definition(*root, file, out);
    for (Diagnostic& d : validate_workflow(result.definition, registry)) {
      out.diagnostics().push_back(std::move(d));
    }
  }
  result.diagnostics = std::move(out.diagnostics());
  std::stable_sort(result.diagnostics.begin(), result.diagnostics.end(),
                   [](const Diagnostic& a, const Diagnostic& b) {
                     return std::pair(a.line, a.column) < std::pair(b.line, b.column);
                   });
  return result;
}

}  // namespace mmm::workflow

#pragma once
// A JSON Schema (draft 2020-12) subset, written in YAML and applied to YAML
// documents, so that the structure of a workflow file is described in one
// machine-readable place (schemas/workflow.schema.yaml) and every structural
// problem is reported with its line and column.
//
// Supported keywords:
//   type (a name or a list; "integer" also satisfies "number"), properties,
//   required, additionalProperties (true, false or a schema),
//   patternProperties, propertyNames (keys are checked as strings), items,
//   minItems, enum and const (scalar values; 1 and 1.0 are equal), pattern
//   (std::regex ECMAScript, searched anywhere in the string as JSON Schema
//   does), minimum, maximum, minLength (code points), $ref ("#" or
//   "#/$defs/NAME"; $defs at the top level), oneOf, anyOf, and the schemas
//   true and false.
// Annotations, accepted and not checked: $schema, $id, $comment, title,
// description, default, examples. A schema's description is appended to the
// messages about values it rejects, as a hint.
// Any other keyword makes the schema itself invalid: a typo in a schema must
// not silently switch a check off.
//
// Values are typed by YAML 1.2's core schema (see yaml_scalar.h): `3` is an
// integer, `'3'` a string, `yes` a string.

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/definition/diagnostic.h"

namespace mmm::workflow {

struct SchemaViolation {
  SourceLocation where;  // of the offending value (of its key when the value is empty)
  std::string path;      // e.g. "nodes[1].params.target_faces"; "top level" for the root
  std::string message;   // e.g. "expected integer, got string 'many'"

  // "path: message"
  [[nodiscard]] std::string text() const;
};

class YamlSchema {
 public:
  // Compiles a schema; `origin` names it in errors. Throws InvalidInputError
  // (origin, schema path, keyword) for an unsupported keyword, a keyword of
  // the wrong shape, a $ref that does not resolve, or a pattern that is not a
  // valid regular expression.
  static YamlSchema from_yaml(const YAML::Node& root, const std::string& origin);
  // Parses YAML text first; a YAML syntax error is an InvalidInputError too.
  static YamlSchema from_text(std::string_view text, const std::string& origin);
  // Reads a schema file; IoError when it cannot be read or parsed.
  static YamlSchema from_file(const std::filesystem::path& file);

  // Every violation of the schema by `document`, in document order (not
  // stopping at the first). Empty when the document is valid.
  [[nodiscard]] std::vector<SchemaViolation> validate(const YAML::Node& document) const;

  struct Compiled;  // defined in the .cpp

 private:
  explicit YamlSchema(std::shared_ptr<const Compiled> compiled);
  std::shared_ptr<const Compiled> compiled_;
};

}  // namespace mmm::workflow

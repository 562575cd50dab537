#pragma once
// Typing of YAML values the way YAML 1.2's core schema (and JSON Schema)
// sees them. yaml-cpp hands every scalar over as text; these helpers decide
// whether a plain scalar is null, a boolean, an integer, a number or a
// string:
//   null      ~  null  Null  NULL  (or nothing)
//   boolean   true  True  TRUE  false  False  FALSE   (not yes/no/on/off)
//   integer   [-+]?[0-9]+  0o[0-7]+  0x[0-9a-fA-F]+   (that fit in 64 bits)
//   number    [-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?  .inf  -.inf  .nan
//   string    everything else, and every quoted scalar ('3' is text)
// Explicit tags (!!str, !!int, !!float, !!bool, !!null) are honoured.

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <string_view>

#include "workflow/definition/diagnostic.h"
#include "workflow/node_spec.h"

namespace mmm::workflow {

enum class YamlKind { kNull, kBool, kInteger, kNumber, kString, kMapping, kSequence };

// JSON-Schema name of a kind: null, boolean, integer, number, string, object,
// array.
std::string_view yaml_kind_name(YamlKind kind);

// Kind of a node; an undefined node (absent key) is kNull.
YamlKind yaml_kind(const YAML::Node& node);

// The value of a scalar as a parameter value: integer -> std::int64_t,
// number -> double, boolean -> bool, string -> std::string. std::nullopt for
// null, mappings and sequences.
std::optional<ParamValue> yaml_param_value(const YAML::Node& node);

// For messages: "integer 12", "string 'abc'", "a mapping", "a sequence",
// "null".
std::string yaml_value_description(const YAML::Node& node);

// 1-based position of a node (yaml-cpp marks are 0-based); unknown for a node
// without a mark.
SourceLocation location_of(const YAML::Node& node);

}  // namespace mmm::workflow

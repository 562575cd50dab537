// The schema is compiled once into a flat list of rules (one per subschema,
// $ref resolved to an index), so a typo or a bad regular expression in the
// schema fails when it is loaded, not when a document happens to reach it.
// Validation walks the document and the rules together and records every
// violation instead of stopping at the first.

#include "workflow/definition/yaml_schema.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <utility>

#include "core/bounded_yaml.h"
#include "core/errors.h"
#include "core/suggest.h"
#include "workflow/definition/yaml_scalar.h"

namespace mmm::workflow {

// The compiled form of a schema. Named, not file-local, because
// YamlSchema::Compiled holds it.
namespace schema_detail {

using TypeMask = unsigned;

struct Pattern {
  std::string source;
  std::regex regex;
};

// A scalar of an enum or const keyword: its kind and value (std::nullopt
// for null), held apart from the YAML tree it came from.
struct Literal {
  YamlKind kind = YamlKind::kNull;
  std::optional<ParamValue> value;
};

// One compiled subschema. Indices refer to YamlSchema::Compiled::rules.
struct Rule {
  bool reject_all = false;  // the schema `false`
  TypeMask types = 0;       // 0: any type
  std::vector<std::string> type_names;
  std::vector<std::pair<std::string, std::size_t>> properties;
  std::vector<std::string> required;
  bool additional_allowed = true;
  std::optional<std::size_t> additional;
  std::vector<std::pair<Pattern, std::size_t>> pattern_properties;
  std::optional<std::size_t> property_names;
  std::optional<std::size_t> items;
  std::optional<std::size_t> min_items;
  std::vector<Literal> enum_values;
  std::optional<Literal> const_value;
  std::optional<Pattern> pattern;
  std::optional<double> minimum;
  std::optional<double> maximum;
  std::optional<std::size_t> min_length;
  std::optional<std::size_t> ref;
  std::vector<std::size_t> one_of;
  std::vector<std::size_t> any_of;
  std::string description;
};

}  // namespace schema_detail

namespace {

using schema_detail::Literal;
using schema_detail::Pattern;
using schema_detail::Rule;
using schema_detail::TypeMask;

TypeMask bit(YamlKind kind) { return 1U << static_cast<unsigned>(kind); }

bool is_numeric(YamlKind kind) { return kind == YamlKind::kInteger || kind == YamlKind::kNumber; }

double numeric_value(const std::optional<ParamValue>& value) {
  if (!value) return 0;
  if (const auto* i = std::get_if<std::int64_t>(&*value)) return static_cast<double>(*i);
  if (const auto* d = std::get_if<double>(&*value)) return *d;
  return 0;
}

Literal literal_of_node(const YAML::Node& node) {
  return {yaml_kind(node), yaml_param_value(node)};
}

// JSON-Schema equality of a value and a literal (1 == 1.0; "1" != 1).
bool equals(const YAML::Node& node, const Literal& literal) {
  const Literal value = literal_of_node(node);
  if (is_numeric(value.kind) && is_numeric(literal.kind)) {
    if (value.kind == YamlKind::kInteger && literal.kind == YamlKind::kInteger) {
      return value.value == literal.value;
    }
    return numeric_value(value.value) == numeric_value(literal.value);
  }
  return value.kind == literal.kind && value.value == literal.value;
}

std::string literal_text(const Literal& literal) {
  if (!literal.value) return "null";
  const std::string text = param_value_text(*literal.value);
  return literal.kind == YamlKind::kString ? "'" + text + "'" : text;
}

std::size_t code_points(std::string_view text) {
  return static_cast<std::size_t>(std::count_if(text.begin(), text.end(), [](char c) {
    return (static_cast<unsigned char>(c) & 0xC0U) != 0x80U;  // not a continuation byte
  }));
}

std::string child_path(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

const std::set<std::string, std::less<>> kAnnotations = {"$schema", "$id",     "$comment",
                                                         "title",   "default", "examples"};

class Compiler {
 public:
  explicit Compiler(std::string origin) : origin_(std::move(origin)) {}

  std::vector<Rule> compile(const YAML::Node& root) {
    add(root, "#", true);
    for (const auto& [rule, ref, path] : pending_refs_) {
      if (ref == "#") {
        rules_[rule].ref = 0;
        continue;
      }
      constexpr std::string_view kDefsPrefix = "#/$defs/";
      const auto it =
          ref.rfind(kDefsPrefix, 0) == 0 ? defs_.find(ref.substr(kDefsPrefix.size())) : defs_.end();
      if (it == defs_.end()) {
        std::vector<std::string> known;
        for (const auto& [name, index] : defs_) known.push_back("#/$defs/" + name);
        fail(path, "$ref '" + ref + "' does not resolve; known: " + join_names(known));
      }
      rules_[rule].ref = it->second;
    }
    return std::move(rules_);
  }

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
    throw InvalidInputError(origin_ + ": schema " + path + ": " + problem);
  }

  std::string text_of(const YAML::Node& node, const std::string& path) const {
    if (yaml_kind(node) != YamlKind::kString) {
      fail(path, "expected a string, got " + yaml_value_description(node));
    }
    return node.Scalar();
  }

  std::size_t count_of(const YAML::Node& node, const std::string& path) const {
    const auto value = yaml_param_value(node);
    const auto* count = value ? std::get_if<std::int64_t>(&*value) : nullptr;
    if (count == nullptr || *count < 0) {
      fail(path, "expected a non-negative integer, got " + yaml_value_description(node));
    }
    return static_cast<std::size_t>(*count);
  }

  double number_of(const YAML::Node& node, const std::string& path) const {
    if (!is_numeric(yaml_kind(node))) {
      fail(path, "expected a number, got " + yaml_value_description(node));
    }
    return numeric_value(yaml_param_value(node));
  }

  Pattern pattern_of(const std::string& source, const std::string& path) const {
    try {
      return {source, std::regex(source, std::regex::ECMAScript)};
    } catch (const std::regex_error& e) {
      fail(path, "pattern '" + source + "' is not a valid ECMAScript regular expression (" +
                     e.what() + ")");
    }
  }

  Literal literal_of(const YAML::Node& node, const std::string& path) const {
    if (!node.IsScalar() && !node.IsNull()) {
      fail(path, "only scalar values are supported in enum and const, got " +
                     yaml_value_description(node));
    }
    return literal_of_node(node);
  }

  std::vector<std::size_t> alternatives(const YAML::Node& node, const std::string& path) {
    if (!node.IsSequence() || node.size() == 0) fail(path, "expected a non-empty list of schemas");
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < node.size(); ++i) {
      out.push_back(add(node[i], path + "/" + std::to_string(i), false));
    }
    return out;
  }

  void set_types(Rule& rule, const YAML::Node& node, const std::string& path) const {
    std::vector<YAML::Node> names;
    if (node.IsSequence()) {
      for (const auto& item : node) names.push_back(item);
    } else {
      names.push_back(node);
    }
    if (names.empty()) fail(path, "type: expected a type name or a non-empty list of them");
    static const std::map<std::string, TypeMask, std::less<>> kTypes = {
        {"null", bit(YamlKind::kNull)},
        {"boolean", bit(YamlKind::kBool)},
        {"integer", bit(YamlKind::kInteger)},
        {"number", bit(YamlKind::kNumber) | bit(YamlKind::kInteger)},
        {"string", bit(YamlKind::kString)},
        {"object", bit(YamlKind::kMapping)},
        {"array", bit(YamlKind::kSequence)}};
    for (const auto& name_node : names) {
      const std::string name = text_of(name_node, path);
      const auto it = kTypes.find(name);
      if (it == kTypes.end()) {
        fail(path, "unknown type '" + name +
                       "'; types: null, boolean, integer, number, string, object, array");
      }
      rule.types |= it->second;
      rule.type_names.push_back(name);
    }
  }

  std::size_t add(const YAML::Node& schema, const std::string& path, bool is_root) {
    const std::size_t index = rules_.size();
    rules_.emplace_back();
    Rule rule;
    const YamlKind kind = yaml_kind(schema);
    if (kind == YamlKind::kBool) {
      rule.reject_all = !std::get<bool>(*yaml_param_value(schema));
      rules_[index] = std::move(rule);
      return index;
    }
    if (kind != YamlKind::kMapping) {
      fail(path, "a schema is a mapping or true/false, got " + yaml_value_description(schema));
    }
    for (const auto& entry : schema) {
      const std::string keyword = entry.first.Scalar();
      const YAML::Node& value = entry.second;
      std::string at = path;
      at += "/";
      at += keyword;
      if (keyword == "type") {
        set_types(rule, value, at);
      } else if (keyword == "properties" || keyword == "patternProperties" || keyword == "$defs") {
        if (!value.IsMap()) fail(at, "expected a mapping of names to schemas");
        if (keyword == "$defs" && !is_root) fail(at, "$defs is supported at the top level only");
        for (const auto& property : value) {
          const std::string name = property.first.Scalar();
          std::string sub_path = at;
          sub_path += "/";
          sub_path += name;
          const std::size_t sub = add(property.second, sub_path, false);
          if (keyword == "properties") {
            rule.properties.emplace_back(name, sub);
          } else if (keyword == "patternProperties") {
            rule.pattern_properties.emplace_back(pattern_of(name, at), sub);
          } else {
            defs_[name] = sub;
          }
        }
      } else if (keyword == "required") {
        if (!value.IsSequence()) fail(at, "expected a list of key names");
        for (const auto& name : value) rule.required.push_back(text_of(name, at));
      } else if (keyword == "additionalProperties") {
        if (yaml_kind(value) == YamlKind::kBool) {
          rule.additional_allowed = std::get<bool>(*yaml_param_value(value));
        } else {
          rule.additional = add(value, at, false);
        }
      } else if (keyword == "propertyNames") {
        rule.property_names = add(value, at, false);
      } else if (keyword == "items") {
        rule.items = add(value, at, false);
      } else if (keyword == "minItems") {
        rule.min_items = count_of(value, at);
      } else if (keyword == "enum") {
        if (!value.IsSequence() || value.size() == 0) fail(at, "expected a non-empty list");
        for (const auto& item : value) rule.enum_values.push_back(literal_of(item, at));
      } else if (keyword == "const") {
        rule.const_value = literal_of(value, at);
      } else if (keyword == "pattern") {
        rule.pattern = pattern_of(text_of(value, at), at);
      } else if (keyword == "minimum") {
        rule.minimum = number_of(value, at);
      } else if (keyword == "maximum") {
        rule.maximum = number_of(value, at);
      } else if (keyword == "minLength") {
        rule.min_length = count_of(value, at);
      } else if (keyword == "$ref") {
        pending_refs_.emplace_back(index, text_of(value, at), at);
      } else if (keyword == "oneOf") {
        rule.one_of = alternatives(value, at);
      } else if (keyword == "anyOf") {
        rule.any_of = alternatives(value, at);
      } else if (keyword == "description") {
        rule.description = text_of(value, at);
      } else if (!kAnnotations.contains(keyword)) {
        fail(at, "unsupported keyword '" + keyword + "'" +
                     did_you_mean(keyword,
                                  {"type", "properties", "required", "additionalProperties",
                                   "patternProperties", "propertyNames", "items", "minItems",
                                   "enum", "const", "pattern", "minimum", "maximum", "minLength",
                                   "$ref", "oneOf", "anyOf", "description", "$defs"}));
      }
    }
    rules_[index] = std::move(rule);
    return index;
  }

  std::string origin_;
  std::vector<Rule> rules_;
  std::map<std::string, std::size_t> defs_;
  std::vector<std::tuple<std::size_t, std::string, std::string>> pending_refs_;
};

class Validator {
 public:
  Validator(const std::vector<Rule>& rules, std::vector<SchemaViolation>& out)
      : rules_(rules), out_(out) {}

  // `where` is the location reported for this value: its own, or its key's
  // when the value is empty (yaml-cpp marks an empty value at the next token).
  void check(const YAML::Node& node, std::size_t index, const std::string& path,
             SourceLocation where) {
    const Rule& rule = rules_[index];
    if (rule.reject_all) {
      report(where, path, "no value is allowed here", rule);
      return;
    }
    const YamlKind kind = yaml_kind(node);
    if (rule.types != 0 && (rule.types & bit(kind)) == 0) {
      std::string expected;
      for (std::size_t i = 0; i < rule.type_names.size(); ++i) {
        if (i > 0) expected += i + 1 == rule.type_names.size() ? " or " : ", ";
        expected += rule.type_names[i];
      }
      report(where, path, "expected " + expected + ", got " + yaml_value_description(node), rule);
      return;  // the other keywords describe values of the right type
    }
    if (rule.ref) check(node, *rule.ref, path, where);
    check_literals(node, rule, path, where);
    if (kind == YamlKind::kString) check_string(node.Scalar(), rule, path, where);
    if (is_numeric(kind)) check_number(node, rule, path, where);
    if (kind == YamlKind::kMapping) check_mapping(node, rule, path, where);
    if (kind == YamlKind::kSequence) check_sequence(node, rule, path, where);
    if (!rule.any_of.empty() || !rule.one_of.empty()) check_alternatives(node, rule, path, where);
  }

 private:
  void report(SourceLocation where, const std::string& path, std::string message,
              const Rule& rule) {
    if (!rule.description.empty()) message += " (" + rule.description + ")";
    out_.push_back({where, path.empty() ? "top level" : path, std::move(message)});
  }

  void check_literals(const YAML::Node& node, const Rule& rule, const std::string& path,
                      SourceLocation where) {
    if (rule.const_value && !equals(node, *rule.const_value)) {
      report(
          where, path,
          "expected " + literal_text(*rule.const_value) + ", got " + yaml_value_description(node),
          rule);
    }
    if (!rule.enum_values.empty() &&
        std::none_of(rule.enum_values.begin(), rule.enum_values.end(),
                     [&](const Literal& v) { return equals(node, v); })) {
      std::string allowed;
      for (const Literal& v : rule.enum_values)
        allowed += (allowed.empty() ? "" : ", ") + literal_text(v);
      report(where, path, "expected one of " + allowed + ", got " + yaml_value_description(node),
             rule);
    }
  }

  void check_string(const std::string& text, const Rule& rule, const std::string& path,
                    SourceLocation where) {
    if (rule.pattern && !std::regex_search(text, rule.pattern->regex)) {
      report(where, path, "'" + text + "' does not match the pattern " + rule.pattern->source,
             rule);
    }
    if (rule.min_length && code_points(text) < *rule.min_length) {
      report(where, path,
             "'" + text + "' is shorter than " + std::to_string(*rule.min_length) + " character(s)",
             rule);
    }
  }

  void check_number(const YAML::Node& node, const Rule& rule, const std::string& path,
                    SourceLocation where) {
    const double value = numeric_value(yaml_param_value(node));
    if (rule.minimum && !(value >= *rule.minimum)) {
      report(where, path, node.Scalar() + " is below the minimum " + number_text(*rule.minimum),
             rule);
    }
    if (rule.maximum && !(value <= *rule.maximum)) {
      report(where, path, node.Scalar() + " is above the maximum " + number_text(*rule.maximum),
             rule);
    }
  }

  void check_mapping(const YAML::Node& node, const Rule& rule, const std::string& path,
                     SourceLocation where) {
    for (const std::string& key : rule.required) {
      if (!node[key].IsDefined()) report(where, path, "missing required key '" + key + "'", rule);
    }
    std::vector<std::string> allowed;
    for (const auto& [name, sub] : rule.properties) allowed.push_back(name);
    for (const auto& entry : node) {
      const YAML::Node& key = entry.first;
      const YAML::Node& value = entry.second;
      const SourceLocation key_where = location_of(key);
      if (!key.IsScalar()) {
        report(key_where, path, "keys must be plain strings, got " + yaml_value_description(key),
               rule);
        continue;
      }
      const std::string& name = key.Scalar();
      const std::string sub_path = child_path(path, name);
      const SourceLocation value_where = value.IsNull() ? key_where : location_of(value);
      if (rule.property_names) {
        YAML::Node as_string(name);
        as_string.SetTag("!");  // property names are strings, whatever they look like
        check(as_string, *rule.property_names, sub_path, key_where);
      }
      bool matched = false;
      for (const auto& [property, sub] : rule.properties) {
        if (property == name) {
          check(value, sub, sub_path, value_where);
          matched = true;
        }
      }
      for (const auto& [pattern, sub] : rule.pattern_properties) {
        if (std::regex_search(name, pattern.regex)) {
          check(value, sub, sub_path, value_where);
          matched = true;
        }
      }
      if (matched) continue;
      if (rule.additional) {
        check(value, *rule.additional, sub_path, value_where);
      } else if (!rule.additional_allowed) {
        out_.push_back({key_where, path.empty() ? "top level" : path,
                        "unknown key '" + name + "'" + did_you_mean(name, allowed) +
                            " (allowed: " + join_names(allowed) + ")"});
      }
    }
  }

  void check_sequence(const YAML::Node& node, const Rule& rule, const std::string& path,
                      SourceLocation where) {
    if (rule.min_items && node.size() < *rule.min_items) {
      report(where, path,
             "expected at least " + std::to_string(*rule.min_items) + " item(s), got " +
                 std::to_string(node.size()),
             rule);
    }
    if (!rule.items) return;
    for (std::size_t i = 0; i < node.size(); ++i) {
      const YAML::Node item = node[i];
      const SourceLocation item_where = item.IsNull() ? where : location_of(item);
      check(item, *rule.items, path + "[" + std::to_string(i) + "]", item_where);
    }
  }

  void check_alternatives(const YAML::Node& node, const Rule& rule, const std::string& path,
                          SourceLocation where) {
    const bool one_of = !rule.one_of.empty();
    const std::vector<std::size_t>& branches = one_of ? rule.one_of : rule.any_of;
    std::vector<std::vector<SchemaViolation>> failures;
    std::size_t passed = 0;
    for (const std::size_t branch : branches) {
      std::vector<SchemaViolation> violations;
      Validator(rules_, violations).check(node, branch, path, where);
      if (violations.empty()) {
        ++passed;
      } else {
        failures.push_back(std::move(violations));
      }
    }
    if (passed == 0) {
      std::string reasons;
      for (std::size_t i = 0; i < failures.size(); ++i) {
        reasons += (i == 0 ? "" : "; ") + std::to_string(i + 1) + ") " + failures[i][0].message;
      }
      report(where, path,
             "matches none of the " + std::to_string(branches.size()) + " alternatives: " + reasons,
             rule);
    } else if (one_of && passed > 1) {
      report(where, path,
             "matches " + std::to_string(passed) + " of the " + std::to_string(branches.size()) +
                 " alternatives, expected exactly one",
             rule);
    }
  }

  static std::string number_text(double value) {
    std::ostringstream out;
    out.precision(17);
    out << value;
    return out.str();
  }

  const std::vector<Rule>& rules_;
  std::vector<SchemaViolation>& out_;
};

}  // namespace

struct YamlSchema::Compiled {
  std::vector<Rule> rules;  // rules[0] is the root schema
};

std::string SchemaViolation::text() const { return path + ": " + message; }

YamlSchema::YamlSchema(std::shared_ptr<const Compiled> compiled) : compiled_(std::move(compiled)) {}

YamlSchema YamlSchema::from_yaml(const YAML::Node& root, const std::string& origin) {
  auto compiled = std::make_shared<Compiled>();
  compiled->rules = Compiler(origin).compile(root);
  return YamlSchema(std::move(compiled));
}

YamlSchema YamlSchema::from_text(std::string_view text, const std::string& origin) {
  YAML::Node root;
  try {
    root = load_yaml(text);
  } catch (const YAML::Exception& e) {
    throw InvalidInputError(origin + ":" + std::to_string(e.mark.line + 1) + ":" +
                            std::to_string(e.mark.column + 1) +
                            ": YAML syntax error in schema: " + e.msg);
  }
  return from_yaml(root, origin);
}

YamlSchema YamlSchema::from_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in || std::filesystem::is_directory(file)) {
    throw IoError(file, "cannot read the schema file");
  }
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  try {
    return from_text(text, file.string());
  } catch (const InvalidInputError& e) {
    throw IoError(file, std::string("invalid schema: ") + e.what());
  }
}

std::vector<SchemaViolation> YamlSchema::validate(const YAML::Node& document) const {
  std::vector<SchemaViolation> out;
  Validator(compiled_->rules, out).check(document, 0, "", location_of(document));
  return out;
}

}  // namespace mmm::workflow

#include "workflow/definition/yaml_scalar.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>

namespace mmm::workflow {
namespace {

constexpr std::string_view kTagPrefix = "tag:yaml.org,2002:";

bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool is_null_text(std::string_view s) {
  return s.empty() || s == "~" || s == "null" || s == "Null" || s == "NULL";
}

std::optional<bool> bool_of(std::string_view s) {
  if (s == "true" || s == "True" || s == "TRUE") return true;
  if (s == "false" || s == "False" || s == "FALSE") return false;
  return std::nullopt;
}

// Integer forms of the core schema; std::nullopt when not one or when the
// value does not fit in 64 bits.
std::optional<std::int64_t> integer_of(std::string_view s) {
  int base = 10;
  std::string_view digits = s;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'o' || s[1] == 'x')) {
    base = s[1] == 'o' ? 8 : 16;
    digits = s.substr(2);
  } else {
    if (!digits.empty() && digits[0] == '+') digits.remove_prefix(1);
    const std::string_view unsigned_part =
        !digits.empty() && digits[0] == '-' ? digits.substr(1) : digits;
    if (unsigned_part.empty() || !std::all_of(unsigned_part.begin(), unsigned_part.end(), is_digit))
      return std::nullopt;
  }
  if (digits.empty()) return std::nullopt;
  std::int64_t value = 0;
  const char* end = digits.data() + digits.size();
  const auto [ptr, error] = std::from_chars(digits.data(), end, value, base);
  if (error != std::errc() || ptr != end) return std::nullopt;
  return value;
}

bool looks_like_float(std::string_view s) {
  std::size_t i = 0;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
  std::size_t mantissa_digits = 0;
  while (i < s.size() && is_digit(s[i])) ++i, ++mantissa_digits;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && is_digit(s[i])) ++i, ++mantissa_digits;
  }
  if (mantissa_digits == 0) return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
    std::size_t exponent_digits = 0;
    while (i < s.size() && is_digit(s[i])) ++i, ++exponent_digits;
    if (exponent_digits == 0) return false;
  }
  return i == s.size();
}

std::optional<double> number_of(std::string_view s) {
  std::string_view body = s;
  bool negative = false;
  if (!body.empty() && (body[0] == '-' || body[0] == '+')) {
    negative = body[0] == '-';
    body.remove_prefix(1);
  }
  if (body == ".inf" || body == ".Inf" || body == ".INF") {
    return negative ? -std::numeric_limits<double>::infinity()
                    : std::numeric_limits<double>::infinity();
  }
  if (s == ".nan" || s == ".NaN" || s == ".NAN") return std::numeric_limits<double>::quiet_NaN();
  if (!looks_like_float(s)) return std::nullopt;
  double value = 0;
  const char* end = body.data() + body.size();
  const auto [ptr, error] = std::from_chars(body.data(), end, value);
  // Out-of-range magnitudes (1e999) are not representable: not a number.
  if (error != std::errc() || ptr != end) return std::nullopt;
  return negative ? -value : value;
}

// A scalar's value resolved by its tag or, for plain scalars, by its text.
struct Resolved {
  YamlKind kind = YamlKind::kString;
  std::int64_t integer = 0;
  double number = 0;
  bool boolean = false;
};

Resolved resolve_scalar(const YAML::Node& node) {
  const std::string& text = node.Scalar();
  const std::string& tag = node.Tag();
  Resolved out;
  std::string_view wanted;     // "" = resolve by text
  if (tag == "!") return out;  // quoted or explicitly non-specific: a string
  if (tag.rfind(kTagPrefix, 0) == 0) wanted = std::string_view(tag).substr(kTagPrefix.size());
  if (wanted == "str") return out;
  if ((wanted.empty() || wanted == "null") && is_null_text(text)) {
    out.kind = YamlKind::kNull;
    return out;
  }
  if (wanted.empty() || wanted == "bool") {
    if (const auto b = bool_of(text)) {
      out.kind = YamlKind::kBool;
      out.boolean = *b;
      return out;
    }
  }
  if (wanted.empty() || wanted == "int") {
    if (const auto i = integer_of(text)) {
      out.kind = YamlKind::kInteger;
      out.integer = *i;
      return out;
    }
  }
  if (wanted.empty() || wanted == "float") {
    if (const auto d = number_of(text)) {
      out.kind = YamlKind::kNumber;
      out.number = *d;
      return out;
    }
  }
  return out;
}

}  // namespace

std::string_view yaml_kind_name(YamlKind kind) {
  switch (kind) {
    case YamlKind::kNull:
      return "null";
    case YamlKind::kBool:
      return "boolean";
    case YamlKind::kInteger:
      return "integer";
    case YamlKind::kNumber:
      return "number";
    case YamlKind::kString:
      return "string";
    case YamlKind::kMapping:
      return "object";
    case YamlKind::kSequence:
      return "array";
  }
  return "unknown";
}

YamlKind yaml_kind(const YAML::Node& node) {
  if (!node.IsDefined()) return YamlKind::kNull;
  switch (node.Type()) {
    case YAML::NodeType::Map:
      return YamlKind::kMapping;
    case YAML::NodeType::Sequence:
      return YamlKind::kSequence;
    case YAML::NodeType::Scalar:
      return resolve_scalar(node).kind;
    default:
      return YamlKind::kNull;
  }
}

std::optional<ParamValue> yaml_param_value(const YAML::Node& node) {
  if (!node.IsDefined() || !node.IsScalar()) return std::nullopt;
  const Resolved r = resolve_scalar(node);
  switch (r.kind) {
    case YamlKind::kBool:
      return ParamValue{r.boolean};
    case YamlKind::kInteger:
      return ParamValue{r.integer};
    case YamlKind::kNumber:
      return ParamValue{r.number};
    case YamlKind::kString:
      return ParamValue{node.Scalar()};
    default:
      return std::nullopt;
  }
}

std::string yaml_value_description(const YAML::Node& node) {
  const YamlKind kind = yaml_kind(node);
  switch (kind) {
    case YamlKind::kNull:
      return "null";
    case YamlKind::kMapping:
      return "a mapping";
    case YamlKind::kSequence:
      return "a sequence";
    case YamlKind::kString:
      return "string '" + node.Scalar() + "'";
    default:
      return std::string(yaml_kind_name(kind)) + " " + node.Scalar();
  }
}

SourceLocation location_of(const YAML::Node& node) {
  if (!node.IsDefined()) return {};
  const YAML::Mark mark = node.Mark();
  if (mark.is_null() || mark.line < 0) return {};
  return {mark.line + 1, mark.column + 1};
}

}  // namespace mmm::workflow

#include "workflow/study/value_text.h"

#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>
#include <variant>

#include "core/errors.h"

namespace mmm::workflow {
namespace {

std::optional<double> parse_number(std::string_view text) {
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::optional<std::int64_t> parse_integer(std::string_view text) {
  std::int64_t value = 0;
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

std::optional<bool> parse_bool(std::string_view text) {
  if (text == "true") return true;
  if (text == "false") return false;
  return std::nullopt;
}

[[noreturn]] void reject(std::string_view what, std::string_view text, std::string_view expected) {
  throw InvalidInputError(std::string(what) + ": '" + std::string(text) + "' is not " +
                          std::string(expected));
}

}  // namespace

ParamValue parse_value_text(PortType type, std::string_view text, std::string_view what) {
  switch (type) {
    case PortType::kNumber:
      if (const auto number = parse_number(text)) return *number;
      reject(what, text, "a finite number (e.g. 0.5, 1e3)");
    case PortType::kInteger:
      if (const auto integer = parse_integer(text)) return *integer;
      reject(what, text, "an integer (e.g. 12)");
    case PortType::kBool:
      if (const auto flag = parse_bool(text)) return *flag;
      reject(what, text, "a boolean (true or false)");
    case PortType::kString:
      return std::string(text);
    default:
      throw InvalidInputError(std::string(what) + ": type " + std::string(port_type_name(type)) +
                              " is not a value type; give a file path");
  }
}

ParamValue parse_param_text(const ParamSpec& spec, std::string_view text, std::string_view what) {
  ParamValue value;
  switch (spec.type) {
    case ParamType::kNumber:
      value = parse_value_text(PortType::kNumber, text, what);
      break;
    case ParamType::kInteger:
      value = parse_value_text(PortType::kInteger, text, what);
      break;
    case ParamType::kBool:
      value = parse_value_text(PortType::kBool, text, what);
      break;
    case ParamType::kString:
    case ParamType::kEnum:
      value = std::string(text);
      break;
  }
  if (const std::optional<std::string> problem = spec.check(value)) {
    throw InvalidInputError(std::string(what) + ": " + *problem);
  }
  return value;
}

std::string value_artifact_bytes(const ParamValue& value) {
  return std::visit([](const auto& v) { return nlohmann::json(v).dump(); }, value);
}

}  // namespace mmm::workflow

#include "workflow/node_spec.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "core/errors.h"

namespace mmm::workflow {
namespace {

bool valid_identifier(std::string_view name) {
  if (name.empty() || !(name[0] >= 'a' && name[0] <= 'z')) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

template <class T>
const T* find_named(const std::vector<T>& items, std::string_view name) {
  const auto it =
      std::find_if(items.begin(), items.end(), [&](const T& item) { return item.name == name; });
  return it == items.end() ? nullptr : &*it;
}

// Shortest text that reads back to the same double (1e-06, not
// 9.99...e-07), in plain decimal notation for everyday magnitudes.
std::string number_text(double value) {
  std::array<char, 400> buffer{};
  const double magnitude = std::abs(value);
  const bool everyday = magnitude == 0 || (magnitude >= 1e-4 && magnitude < 1e15);
  const auto result = everyday ? std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                               std::chars_format::fixed)
                               : std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return {buffer.data(), result.ptr};
}

}  // namespace

std::string_view param_type_name(ParamType type) {
  switch (type) {
    case ParamType::kNumber:
      return "number";
    case ParamType::kInteger:
      return "integer";
    case ParamType::kString:
      return "string";
    case ParamType::kBool:
      return "bool";
    case ParamType::kEnum:
      return "enum";
  }
  return "unknown";
}

std::string param_value_text(const ParamValue& value) {
  struct Visitor {
    std::string operator()(double v) const { return number_text(v); }
    std::string operator()(std::int64_t v) const { return std::to_string(v); }
    std::string operator()(const std::string& v) const { return v; }
    std::string operator()(bool v) const { return v ? "true" : "false"; }
  };
  return std::visit(Visitor{}, value);
}

std::optional<std::string> ParamSpec::check(const ParamValue& value) const {
  const auto in_range = [&](double v) -> std::optional<std::string> {
    if (v < range.min || v > range.max) {
      return "value " + number_text(v) + " is outside the range [" + number_text(range.min) + ", " +
             number_text(range.max) + "]";
    }
    return std::nullopt;
  };
  switch (type) {
    case ParamType::kNumber:
      if (const auto* v = std::get_if<double>(&value)) {
        if (!std::isfinite(*v)) return "expects a finite number";
        return in_range(*v);
      }
      if (const auto* v = std::get_if<std::int64_t>(&value)) {
        return in_range(static_cast<double>(*v));
      }
      return "expects a number, got '" + param_value_text(value) + "'";
    case ParamType::kInteger:
      if (const auto* v = std::get_if<std::int64_t>(&value)) {
        return in_range(static_cast<double>(*v));
      }
      return "expects an integer, got '" + param_value_text(value) + "'";
    case ParamType::kBool:
      if (std::holds_alternative<bool>(value)) return std::nullopt;
      return "expects true or false, got '" + param_value_text(value) + "'";
    case ParamType::kString:
      if (std::holds_alternative<std::string>(value)) return std::nullopt;
      return "expects a string, got '" + param_value_text(value) + "'";
    case ParamType::kEnum: {
      const auto* v = std::get_if<std::string>(&value);
      if (v != nullptr && std::find(choices.begin(), choices.end(), *v) != choices.end()) {
        return std::nullopt;
      }
      std::string allowed;
      for (const auto& choice : choices) allowed += (allowed.empty() ? "" : ", ") + choice;
      return "expects one of {" + allowed + "}, got '" + param_value_text(value) + "'";
    }
  }
  return "unknown parameter type";
}

NodeSpec::NodeSpec(std::string name, int version, std::string description)
    : name_(std::move(name)), version_(version), description_(std::move(description)) {
  if (!valid_identifier(name_)) {
    throw InvalidInputError("node type name '" + name_ +
                            "' must be lower_snake_case (a-z, 0-9, _; starting with a letter)");
  }
  if (version_ < 1) throw InvalidInputError("node type " + name_ + ": version must be >= 1");
}

NodeSpec& NodeSpec::param_enum(std::string name, std::string default_choice,
                               std::vector<std::string> choices, std::string description) {
  ParamSpec spec{std::move(name),
                 ParamType::kEnum,
                 std::move(default_choice),
                 std::move(description),
                 {},
                 {},
                 std::move(choices)};
  return add_param(std::move(spec));
}

NodeSpec& NodeSpec::manual(bool is_manual) {
  manual_ = is_manual;
  return *this;
}

NodeSpec& NodeSpec::resources(int threads, int memory_mb) {
  if (threads < 1 || memory_mb < 64) {
    throw InvalidInputError("node type '" + name_ + "': resources need at least 1 thread and " +
                            "64 MB (got " + std::to_string(threads) + " threads, " +
                            std::to_string(memory_mb) + " MB)");
  }
  resources_ = {threads, memory_mb};
  return *this;
}

const PortSpec* NodeSpec::find_input(std::string_view name) const {
  return find_named(inputs_, name);
}
const PortSpec* NodeSpec::find_output(std::string_view name) const {
  return find_named(outputs_, name);
}
const ParamSpec* NodeSpec::find_param(std::string_view name) const {
  return find_named(params_, name);
}

NodeSpec& NodeSpec::add_input(PortSpec port) {
  if (!valid_identifier(port.name) || find_input(port.name) != nullptr) {
    throw InvalidInputError("node type " + name_ + ": input name '" + port.name +
                            "' is not a unique lower_snake_case identifier");
  }
  inputs_.push_back(std::move(port));
  return *this;
}

NodeSpec& NodeSpec::add_output(PortSpec port) {
  if (!valid_identifier(port.name) || find_output(port.name) != nullptr) {
    throw InvalidInputError("node type " + name_ + ": output name '" + port.name +
                            "' is not a unique lower_snake_case identifier");
  }
  outputs_.push_back(std::move(port));
  return *this;
}

NodeSpec& NodeSpec::add_param(ParamSpec param) {
  if (!valid_identifier(param.name) || find_param(param.name) != nullptr) {
    throw InvalidInputError("node type " + name_ + ": parameter name '" + param.name +
                            "' is not a unique lower_snake_case identifier");
  }
  if (const auto problem = param.check(param.default_value)) {
    throw InvalidInputError("node type " + name_ + ": default of parameter '" + param.name + "' " +
                            *problem);
  }
  params_.push_back(std::move(param));
  return *this;
}

}  // namespace mmm::workflow

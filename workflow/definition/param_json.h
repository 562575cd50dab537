#pragma once
// A parameter value as a plain JSON scalar, for the JSON forms of
// workflow/definition/ (node_catalog.cpp, workflow_definition.cpp). Not part
// of the public contract.

#include <nlohmann/json.hpp>
#include <variant>

#include "workflow/node_spec.h"

namespace mmm::workflow::detail {

// 0.5, 3, "text" or true as such (unlike the tagged param_value_json of
// workflow/study/cache_key.h).
inline nlohmann::json value_json(const ParamValue& value) {
  return std::visit([](const auto& v) { return nlohmann::json(v); }, value);
}

}  // namespace mmm::workflow::detail

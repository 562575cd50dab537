#pragma once
// What a manual node type makes of a person's submission: the reasons to
// reject it (none: acceptable), the values to show and audit, and the bytes
// of each output port recorded as the node's result once accepted.

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "workflow/port_type.h"

namespace mmm::worklists {

struct ManualOutput {
  workflow::PortType type = workflow::PortType::kFile;
  std::string bytes;
};

// NOLINTNEXTLINE(bugprone-exception-escape): nlohmann::json's noexcept move only asserts
struct ManualEvaluation {
  std::vector<std::string> reasons;
  nlohmann::json values;
  std::map<std::string, ManualOutput> outputs;  // port -> value (empty when rejected)
};

}  // namespace mmm::worklists

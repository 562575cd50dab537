#include "worklists/task.h"

#include <array>
#include <utility>

namespace mmm::worklists {
namespace {

constexpr std::array<std::pair<TaskState, std::string_view>, 5> kStateNames = {{
    {TaskState::kOpen, "open"},
    {TaskState::kClaimed, "claimed"},
    {TaskState::kSubmitted, "submitted"},
    {TaskState::kAccepted, "accepted"},
    {TaskState::kCancelled, "cancelled"},
}};

}  // namespace

std::string_view task_state_name(TaskState state) {
  for (const auto& [value, name] : kStateNames) {
    if (value == state) return name;
  }
  return "unknown";
}

std::optional<TaskState> task_state_from_name(std::string_view name) {
  for (const auto& [value, state_name] : kStateNames) {
    if (state_name == name) return value;
  }
  return std::nullopt;
}

std::string task_state_names() {
  std::string text;
  for (const auto& [value, name] : kStateNames) {
    text += (text.empty() ? "" : ", ") + std::string(name);
  }
  return text;
}

nlohmann::json task_to_json(const Task& task) {
  return {{"id", task.id},
          {"node", task.node},
          {"node_type", task.node_type},
          {"cache_key", task.cache_key},
          {"state", task_state_name(task.state)},
          {"assignee", task.assignee},
          {"created_at", task.created_at},
          {"updated_at", task.updated_at},
          {"request", task.request},
          {"submission", task.submission},
          {"result", task.result},
          {"rejection_reasons", task.rejection_reasons},
          {"submitted_by", task.submitted_by},
          {"pending_correction", task.pending_correction},
          {"revision", task.revision}};
}

}  // namespace mmm::worklists

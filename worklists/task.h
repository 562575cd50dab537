#pragma once
// A manual task: the work a manual workflow node (e.g. the landmark station)
// waits for, kept in the study database beside the executions.
//
//   open --claim--> claimed --submit--> submitted --accept--> accepted
//     ^               |                    |
//     +---release-----+                    +--reject (reasons)--> open
//   any state but accepted --cancel--> cancelled
//
// A submission that fails validation is rejected at once (back to open, with
// every reason); one that passes is accepted at once unless the node asks for
// a second person's review (then it waits in 'submitted'). A later submission
// for an accepted task is a correction: it needs a reason, supersedes the old
// values and re-runs exactly the downstream nodes; when the node asks for
// review, the correction waits for a second person too (the task stays
// accepted with its old values meanwhile).
//
// The assignee is kept apart from the state (Camunda's lesson): a claimed
// task has one; releasing clears it; reassigning changes it without a detour
// through 'open'.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/study/cache_key.h"

namespace mmm::worklists {

enum class TaskState { kOpen, kClaimed, kSubmitted, kAccepted, kCancelled };
std::string_view task_state_name(TaskState state);
// std::nullopt for an unknown name.
std::optional<TaskState> task_state_from_name(std::string_view name);
// "open, claimed, submitted, accepted, cancelled", for hints.
std::string task_state_names();

struct Task {
  std::string id;         // 10 lowercase hex characters, unique across studies
  std::string node;       // the manual workflow node it belongs to
  std::string node_type;  // the manual node type: its task behaviour reads the request
  // The node's cache key (and its parts: parameters, input hashes) when the
  // task opened: a result is recorded under this key.
  std::string cache_key;
  workflow::CacheKeyParts key_parts;
  TaskState state = TaskState::kOpen;
  std::string assignee;  // empty unless claimed/submitted/accepted
  std::string created_at;
  std::string updated_at;
  // What is needed, for the operator (names, images, instructions): the
  // node type's own document, built by its task behaviour (with "kind").
  nlohmann::json request = nlohmann::json::object();
  nlohmann::json submission;                   // the latest submission as given (null: none)
  nlohmann::json result;                       // the accepted values (null: none)
  std::vector<std::string> rejection_reasons;  // of the latest rejection
  // Who submitted the values that await review or were accepted (the
  // reviewer can never be this operator, whoever the task is assigned to).
  std::string submitted_by;
  // A correction of accepted values that awaits review (nodes with review):
  // {"submission", "reason", "by"}; null when none. The accepted values stay
  // in force until a second operator accepts it.
  nlohmann::json pending_correction;
  std::int64_t result_execution = 0;  // execution row of the accepted result
  int revision = 0;                   // +1 at every change
};

nlohmann::json task_to_json(const Task& task);

}  // namespace mmm::worklists

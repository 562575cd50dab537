#pragma once
// What operators (and the runner) do to manual tasks, one transaction each:
// the task row changes, its audit entry is appended (audit_trail.h) and, when
// values are accepted, the manual node's result is recorded as an execution
// of the node under the task's cache key — so the next run finds it and the
// downstream nodes start. After the commit the audit checkpoint file is
// rewritten.
//
// Errors: TaskError (an InvalidInputError) for what the operator can fix
// (wrong state, task claimed by someone else, missing reason), with a hint.
// A submission that fails validation is not an error: it is rejected, with
// every reason, and the task goes back to the operator.

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "workflow/study/study.h"
#include "worklists/task.h"

namespace mmm::worklists {

class TaskError : public InvalidInputError {
 public:
  using InvalidInputError::InvalidInputError;
};

// Who acts, recorded in the audit trail.
struct Actor {
  std::string operator_name;  // letters, digits, '.', '_', '-', '@'; 1-64 characters
  std::string mmm_version;
  bool supervisor = false;  // registered with the supervisor role (operators.h)
  // Non-empty: acting without the operator's token, by administrative
  // override (the command line's --admin-override); each action is preceded
  // in the audit trail by an "override" entry with this reason.
  std::string override_reason{};
};

// The name the runner acts under when it opens or cancels tasks.
inline constexpr const char* kSystemOperator = "mmm";

// Names no operator may have: the runner's own and those that would read as
// the system's in the audit trail (compared without regard to case).
inline constexpr std::array<std::string_view, 7> kReservedOperatorNames = {
    "mmm", "system", "root", "admin", "administrator", "nobody", "anonymous"};

// Throws TaskError unless `name` is a valid operator name that is not
// reserved.
void check_operator_name(const std::string& name);

// Prepares the tasks and audit tables of a study (idempotent).
void prepare_worklist_tables(workflow::Study& study);

// After a run: opens a task for every manual node that waits for a person
// and has none for its current cache key, and cancels the open/claimed tasks
// of a node whose inputs or parameters changed since (their values would
// belong to other images). Returns the tasks opened.
std::vector<Task> open_waiting_tasks(workflow::Study& study, const Actor& actor);

Task claim_task(workflow::Study& study, const std::string& id, const Actor& actor);
Task release_task(workflow::Study& study, const std::string& id, const Actor& actor);
// Release, reassign and cancel of a task that has an assignee (claimed or
// submitted): only the assignee or a supervisor; the audit says who. An open
// task may be cancelled by any operator. Reasons are never blank.
// Reassigning hands the task to `to`; it never makes the submitter of the
// values awaiting review their reviewer.
Task reassign_task(workflow::Study& study, const std::string& id, const Actor& actor,
                   const std::string& to);
Task cancel_task(workflow::Study& study, const std::string& id, const Actor& actor,
                 const std::string& reason);

struct SubmitOutcome {
  Task task;
  bool accepted = false;    // values recorded as the node's result
  bool correction = false;  // the task was already accepted: these values supersede
  bool awaiting_review = false;
  std::vector<std::string> reasons;  // why it was rejected (empty when not)
  nlohmann::json values;             // what was computed from the submission (e.g. 3-D points)
};

// The task behaviour of the task's node type (workflow/manual_task.h):
// what its request shows and how a submission is evaluated. Throws
// TaskError when the study's registry has no manual node type of that name.
const workflow::ManualTaskBehaviour& task_behaviour(const workflow::Study& study, const Task& task);

// Submits values for a task the operator has claimed, or corrects an accepted
// task (then a non-blank `reason` is required; with a review node the
// correction awaits review and the accepted values stay in force). The
// submission is evaluated by the node type's task behaviour.
SubmitOutcome submit_task(workflow::Study& study, const std::string& id, const Actor& actor,
                          const nlohmann::json& submission, const std::string& reason = {});

// Review (nodes with review = true): a second operator accepts or rejects a
// submitted task or a pending correction; the submitter can never review
// their own work, whoever the task is assigned to. Rejecting a correction
// keeps the accepted values; rejecting a first submission reopens the task.
SubmitOutcome accept_task(workflow::Study& study, const std::string& id, const Actor& actor);
Task reject_task(workflow::Study& study, const std::string& id, const Actor& actor,
                 const std::vector<std::string>& reasons);

// Computes what a submission would give without recording anything (the web
// page's live reprojection error).
SubmitOutcome preview_submission(workflow::Study& study, const std::string& id,
                                 const nlohmann::json& submission);

}  // namespace mmm::worklists

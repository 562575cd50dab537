#include "worklists/task_actions.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <optional>
#include <utility>

#include "workflow/host_and_time.h"
#include "workflow/run/study_plan.h"
#include "workflow/study/execution_records.h"
#include "worklists/audit_trail.h"
#include "worklists/manual_evaluation.h"
#include "worklists/task_store.h"

namespace mmm::worklists {
namespace {

using Json = nlohmann::json;
using workflow::Study;
using workflow::Transaction;

std::string state_text(const Task& task) {
  std::string text = "task " + task.id + " is " + std::string(task_state_name(task.state));
  if (!task.assignee.empty()) text += " (assignee " + task.assignee + ")";
  return text;
}

Task load(Study& study, const std::string& id) {
  std::optional<Task> task = find_task(study.database(), id);
  if (!task) {
    throw TaskError("study " + study.dir().string() + " has no task " + id +
                    "; hint: 'mmm worklist --root DIR' lists the tasks");
  }
  return std::move(*task);
}

// The image hashes the operator saw, for the audit trail.
Json images_of(const Task& task) { return task.request.value("images", Json::object()); }

// Appends the audit entry of one action (inside the caller's transaction).
void audit(Study& study, const Actor& actor, const Task& task, const std::string& action,
           const Json& before, const Json& after, const std::string& reason) {
  if (!actor.override_reason.empty()) {
    AuditEntry override_entry;
    override_entry.action = "override";
    override_entry.operator_name = actor.operator_name;
    override_entry.task_id = task.id;
    override_entry.reason =
        "administrative override for '" + action + "': " + actor.override_reason;
    override_entry.mmm_version = actor.mmm_version;
    append_audit_entry(study.database(), std::move(override_entry));
  }
  AuditEntry entry;
  entry.action = action;
  entry.operator_name = actor.operator_name;
  entry.task_id = task.id;
  entry.reason = reason;
  entry.mmm_version = actor.mmm_version;
  entry.before = before;
  entry.after = after;
  entry.images = images_of(task);
  append_audit_entry(study.database(), std::move(entry));
}

// Writes the changed task (revision + 1). Throws TaskError when another
// process changed it since it was read (the loser of a race).
void save(Study& study, Task& task) {
  task.updated_at = workflow::utc_now_precise();
  ++task.revision;
  if (!update_task(study.database(), task)) {
    throw TaskError("task " + task.id + " was changed by someone else meanwhile; hint: look at " +
                    "it again ('mmm task show " + task.id + "')");
  }
}

// One action: a write transaction around `change`, then the checkpoint.
template <class Change>
auto act(Study& study, const std::string& id, Change&& change) {
  Transaction transaction(study.database());
  Task task = load(study, id);
  auto result = change(task);
  transaction.commit();
  write_audit_checkpoint(study.dir(), study.database());
  return result;
}

std::string join(const std::vector<std::string>& reasons) {
  std::string text;
  for (const std::string& reason : reasons) text += (text.empty() ? "" : "; ") + reason;
  return text;
}

ManualEvaluation evaluate(const Study& study, const Task& task, const Json& submission) {
  return task_behaviour(study, task).evaluate(task.request, submission);
}

// Records the evaluated values as the manual node's result: an execution
// row under the task's cache key, its outputs put in the artifact store.
std::int64_t record_result(Study& study, const Task& task, const Actor& actor,
                           const ManualEvaluation& evaluation, const std::string& why) {
  workflow::ExecutionRecord record;
  record.node = task.node;
  record.node_type = task.node_type;
  record.version = task.key_parts.version;
  record.cache_key = task.cache_key;
  record.key_parts = task.key_parts;
  for (const auto& [port, output] : evaluation.outputs) {
    record.outputs[port] = {output.type, study.artifacts().put(output.bytes)};
  }
  record.status = workflow::ExecutionStatus::kRunning;
  record.manual = true;
  record.reason = why;
  record.started_at = record.finished_at = workflow::utc_now_precise();
  record.host = workflow::host_name();
  record.pid = ::getpid();
  record.submitted_by = actor.operator_name;
  const std::int64_t id = insert_execution(study.database(), record);
  record.status = workflow::ExecutionStatus::kDone;
  workflow::finish_execution(study.database(), id, record,
                             {{record.finished_at, workflow::LogLevel::kInfo, why}});
  return id;
}

void require_operator(const Task& task, const Actor& actor, const std::string& what) {
  if (task.assignee != actor.operator_name) {
    throw TaskError(state_text(task) + "; only its assignee can " + what +
                    " it; hint: 'mmm task claim " + task.id + "' first, or ask " +
                    (task.assignee.empty() ? std::string("a supervisor") : task.assignee) +
                    " to release or reassign it");
  }
}

// Rule: a task someone has claimed is released, reassigned or cancelled by
// that person or by a supervisor, nobody else.
void require_assignee_or_supervisor(const Task& task, const Actor& actor, const std::string& what) {
  if (task.assignee.empty() || task.assignee == actor.operator_name || actor.supervisor) return;
  throw TaskError(state_text(task) + "; only " + task.assignee + " or a supervisor can " + what +
                  " it (rule: assignee or supervisor); hint: ask " + task.assignee +
                  ", or a supervisor ('mmm operator add NAME --supervisor')");
}

// Who submitted the values awaiting review: recorded with the task, or, for a
// task submitted by an older mmm, the operator of its last "submit" entry.
std::string submitter_of(Study& study, const Task& task) {
  if (!task.submitted_by.empty()) return task.submitted_by;
  return last_operator_of(study.database(), task.id, "submit").value_or(task.assignee);
}

// Rule: the reviewer of values is never the operator who submitted them.
void require_second_operator(const std::string& submitter, const Task& task, const Actor& actor) {
  if (submitter == actor.operator_name) {
    throw TaskError("task " + task.id + ": these values were submitted by " + actor.operator_name +
                    ", who cannot review them (rule: four eyes, whoever the task is assigned "
                    "to); hint: a second operator accepts or rejects them");
  }
}

bool is_blank(const std::string& text) {
  return std::all_of(text.begin(), text.end(),
                     [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; });
}

// Rule: a reason is never blank.
void require_reason(const std::string& reason, const std::string& what) {
  if (is_blank(reason)) {
    throw TaskError(what +
                    " needs a reason that says why (--reason \"...\"); a blank one is "
                    "not a reason");
  }
}

bool review_required(const Task& task) {
  return task.key_parts.params.contains("review") &&
         std::get<bool>(task.key_parts.params.at("review"));
}

// Records `evaluation` as the task's accepted values. `submitter` gave them;
// `actor` accepts them (the submitter themselves, or the reviewer).
SubmitOutcome accept_values(Study& study, Task& task, const Actor& actor,
                            const ManualEvaluation& evaluation, const Json& submission,
                            bool correction, const std::string& submitter,
                            const std::string& reason) {
  SubmitOutcome outcome;
  const Json before = task.result;
  const std::string reviewed =
      submitter == actor.operator_name ? "" : ", reviewed by " + actor.operator_name;
  const std::string why = correction ? "correction by " + submitter + reviewed + ": " + reason
                                     : "submitted by " + submitter + ", accepted" + reviewed;
  task.result_execution = record_result(study, task, actor, evaluation, why);
  task.result = evaluation.values;
  task.submission = submission;
  task.submitted_by = submitter;
  task.pending_correction = nullptr;
  task.state = TaskState::kAccepted;
  task.rejection_reasons.clear();
  save(study, task);
  audit(study, actor, task, correction ? "correct" : "accept", before, task.result, reason);
  outcome.accepted = true;
  outcome.correction = correction;
  outcome.values = evaluation.values;
  outcome.task = task;
  return outcome;
}

}  // namespace

const workflow::ManualTaskBehaviour& task_behaviour(const Study& study, const Task& task) {
  const workflow::NodeType* type = study.registry().find(task.node_type);
  if (type == nullptr || !type->task.complete()) {
    throw TaskError("task " + task.id + " belongs to node type '" + task.node_type +
                    "', which this mmm does not know as a manual node; hint: 'mmm nodes' lists "
                    "the node types (an mmm of the study's version handles the task)");
  }
  return type->task;
}

void check_operator_name(const std::string& name) {
  const bool valid =
      !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == '_' ||
               c == '-' || c == '@';
      });
  if (!valid) {
    throw TaskError("operator name '" + name +
                    "' is not valid; hint: 1-64 letters, digits, '.', '_', '-' or '@'");
  }
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  if (std::find(kReservedOperatorNames.begin(), kReservedOperatorNames.end(), lower) !=
      kReservedOperatorNames.end()) {
    throw TaskError("operator name '" + name +
                    "' is reserved (it would read as mmm itself in the audit trail); hint: use "
                    "the person's own name");
  }
}

void prepare_worklist_tables(Study& study) {
  {
    Transaction transaction(study.database());
    prepare_task_tables(study.database());
    transaction.commit();
  }
  open_audit_trail(study.database(), study.dir());
}

std::vector<Task> open_waiting_tasks(Study& study, const Actor& actor) {
  prepare_worklist_tables(study);
  const workflow::StudyPlan plan = workflow::plan_study(study, false);
  std::vector<Task> opened;
  bool changed = false;
  Transaction transaction(study.database());
  for (const workflow::NodePlan& node : plan.nodes) {
    if (!node.type->spec.is_manual() || !node.key_parts) continue;
    bool has_current = false;
    for (Task& task : tasks_of_node(study.database(), node.node->id)) {
      if (task.cache_key == node.cache_key) {
        has_current = true;
      } else if (task.state == TaskState::kOpen || task.state == TaskState::kClaimed ||
                 task.state == TaskState::kSubmitted) {
        const Json before = task.submission;
        task.state = TaskState::kCancelled;
        save(study, task);
        audit(study, actor, task, "cancel", before, nullptr,
              "the node's inputs or parameters changed: a new task replaces this one");
        changed = true;
      }
    }
    if (has_current || node.state != workflow::NodeState::kWaiting) continue;
    Task task;
    task.id = new_task_id();
    task.node = node.node->id;
    task.node_type = node.type->spec.name();
    task.cache_key = node.cache_key;
    task.key_parts = *node.key_parts;
    task.state = TaskState::kOpen;
    task.created_at = task.updated_at = workflow::utc_now_precise();
    const workflow::ManualTaskBehaviour& behaviour = node.type->task;
    if (behaviour.request) {
      task.request = behaviour.request(task.key_parts, study.artifacts());
      task.request["kind"] = behaviour.kind;
    }
    insert_task(study.database(), task);
    audit(study, actor, task, "open", nullptr, task.request, "");
    opened.push_back(task);
    changed = true;
  }
  transaction.commit();
  if (changed) write_audit_checkpoint(study.dir(), study.database());
  return opened;
}

Task claim_task(Study& study, const std::string& id, const Actor& actor) {
  check_operator_name(actor.operator_name);
  return act(study, id, [&](Task& task) {
    if (task.state != TaskState::kOpen) {
      throw TaskError(state_text(task) + ", it cannot be claimed" +
                      (task.state == TaskState::kClaimed
                           ? "; hint: ask " + task.assignee + " to release it"
                           : std::string()));
    }
    task.state = TaskState::kClaimed;
    task.assignee = actor.operator_name;
    save(study, task);
    audit(study, actor, task, "claim", nullptr, nullptr, "");
    return task;
  });
}

Task release_task(Study& study, const std::string& id, const Actor& actor) {
  check_operator_name(actor.operator_name);
  return act(study, id, [&](Task& task) {
    if (task.state != TaskState::kClaimed) {
      throw TaskError(state_text(task) + ", only a claimed task can be released");
    }
    require_assignee_or_supervisor(task, actor, "release");
    task.state = TaskState::kOpen;
    task.assignee.clear();
    save(study, task);
    audit(study, actor, task, "release", nullptr, nullptr, "");
    return task;
  });
}

Task reassign_task(Study& study, const std::string& id, const Actor& actor, const std::string& to) {
  check_operator_name(actor.operator_name);
  check_operator_name(to);
  return act(study, id, [&](Task& task) {
    if (task.state != TaskState::kClaimed && task.state != TaskState::kSubmitted) {
      throw TaskError(state_text(task) +
                      ", only a claimed or submitted task can be reassigned; hint: an open task "
                      "is claimed by whoever takes it");
    }
    require_assignee_or_supervisor(task, actor, "reassign");
    const Json before = {{"assignee", task.assignee}};
    task.assignee = to;
    save(study, task);
    audit(study, actor, task, "reassign", before, {{"assignee", to}}, "");
    return task;
  });
}

Task cancel_task(Study& study, const std::string& id, const Actor& actor,
                 const std::string& reason) {
  check_operator_name(actor.operator_name);
  require_reason(reason, "cancelling a task");
  return act(study, id, [&](Task& task) {
    if (task.state == TaskState::kAccepted || task.state == TaskState::kCancelled) {
      throw TaskError(state_text(task) + ", it cannot be cancelled");
    }
    require_assignee_or_supervisor(task, actor, "cancel");
    task.state = TaskState::kCancelled;
    save(study, task);
    audit(study, actor, task, "cancel", task.submission, nullptr, reason);
    return task;
  });
}

SubmitOutcome submit_task(Study& study, const std::string& id, const Actor& actor,
                          const Json& submission, const std::string& reason) {
  check_operator_name(actor.operator_name);
  return act(study, id, [&](Task& task) {
    const bool correction = task.state == TaskState::kAccepted;
    if (correction && is_blank(reason)) {
      throw TaskError("task " + task.id + " is already accepted: a correction needs a reason " +
                      "that says why (--reason \"...\"); it supersedes the values of " +
                      task.submitted_by + " and re-runs the downstream nodes");
    }
    if (correction && !task.pending_correction.is_null()) {
      throw TaskError("task " + task.id + " already has a correction by " +
                      task.pending_correction.value("by", "") +
                      " awaiting review; hint: a second operator accepts or rejects it first");
    }
    if (!correction) {
      if (task.state != TaskState::kClaimed) {
        throw TaskError(state_text(task) + ", values can only be submitted for a claimed task" +
                        (task.state == TaskState::kOpen
                             ? "; hint: 'mmm task claim " + task.id + "' first"
                             : std::string()));
      }
      require_operator(task, actor, "submit for");
    }
    const ManualEvaluation evaluation = evaluate(study, task, submission);
    audit(study, actor, task, "submit", task.result, submission, reason);
    if (!evaluation.reasons.empty()) {
      SubmitOutcome outcome;
      outcome.reasons = evaluation.reasons;
      outcome.correction = correction;
      outcome.values = evaluation.values;
      if (!correction) {
        task.state = TaskState::kOpen;
        task.assignee.clear();
        task.submission = submission;
        task.rejection_reasons = evaluation.reasons;
        save(study, task);
      }
      audit(study, actor, task, "reject", submission, nullptr, join(evaluation.reasons));
      outcome.task = task;
      return outcome;
    }
    if (review_required(task)) {
      if (correction) {
        // The accepted values stay in force until a second operator agrees.
        task.pending_correction = {
            {"submission", submission}, {"reason", reason}, {"by", actor.operator_name}};
      } else {
        task.state = TaskState::kSubmitted;
        task.submission = submission;
        task.submitted_by = actor.operator_name;
      }
      task.rejection_reasons.clear();
      save(study, task);
      SubmitOutcome outcome;
      outcome.awaiting_review = true;
      outcome.correction = correction;
      outcome.values = evaluation.values;
      outcome.task = task;
      return outcome;
    }
    return accept_values(study, task, actor, evaluation, submission, correction,
                         actor.operator_name, reason);
  });
}

SubmitOutcome accept_task(Study& study, const std::string& id, const Actor& actor) {
  check_operator_name(actor.operator_name);
  return act(study, id, [&](Task& task) {
    const bool correction =
        task.state == TaskState::kAccepted && !task.pending_correction.is_null();
    if (task.state != TaskState::kSubmitted && !correction) {
      throw TaskError(state_text(task) + ", only a submitted task or a correction awaits review");
    }
    const Json submission = correction ? task.pending_correction.at("submission") : task.submission;
    const std::string submitter =
        correction ? task.pending_correction.value("by", "") : submitter_of(study, task);
    require_second_operator(submitter, task, actor);
    const ManualEvaluation evaluation = evaluate(study, task, submission);
    if (!evaluation.reasons.empty()) {
      throw TaskError("task " + task.id +
                      "'s submission no longer validates: " + join(evaluation.reasons));
    }
    const std::string reason =
        correction ? task.pending_correction.value("reason", "") : std::string("reviewed");
    return accept_values(study, task, actor, evaluation, submission, correction, submitter, reason);
  });
}

Task reject_task(Study& study, const std::string& id, const Actor& actor,
                 const std::vector<std::string>& reasons) {
  check_operator_name(actor.operator_name);
  if (reasons.empty()) throw TaskError("rejecting a task needs at least one reason (--reason)");
  for (const std::string& reason : reasons) require_reason(reason, "rejecting a task");
  return act(study, id, [&](Task& task) {
    const bool correction =
        task.state == TaskState::kAccepted && !task.pending_correction.is_null();
    if (task.state != TaskState::kSubmitted && !correction) {
      throw TaskError(state_text(task) +
                      ", only a submitted task or a correction can be rejected by a reviewer");
    }
    if (correction) {
      require_second_operator(task.pending_correction.value("by", ""), task, actor);
      const Json rejected = task.pending_correction.at("submission");
      task.pending_correction = nullptr;  // the accepted values stay
      task.rejection_reasons = reasons;
      save(study, task);
      audit(study, actor, task, "reject", rejected, nullptr, join(reasons));
      return task;
    }
    require_second_operator(submitter_of(study, task), task, actor);
    task.state = TaskState::kOpen;
    task.assignee.clear();
    task.rejection_reasons = reasons;
    save(study, task);
    audit(study, actor, task, "reject", task.submission, nullptr, join(reasons));
    return task;
  });
}

SubmitOutcome preview_submission(Study& study, const std::string& id, const Json& submission) {
  const Task task = load(study, id);
  const workflow::ManualTaskBehaviour& behaviour = task_behaviour(study, task);
  const ManualEvaluation evaluation = behaviour.preview
                                          ? behaviour.preview(task.request, submission)
                                          : behaviour.evaluate(task.request, submission);
  SubmitOutcome outcome;
  outcome.task = task;
  outcome.reasons = evaluation.reasons;
  outcome.values = evaluation.values;
  return outcome;
}

}  // namespace mmm::worklists

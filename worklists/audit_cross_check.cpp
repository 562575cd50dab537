#include "worklists/audit_cross_check.h"

#include <map>
#include <optional>
#include <string>

#include "core/bounded_json.h"
#include "core/hash/sha256.h"
#include "workflow/store/artifact_store.h"
#include "workflow/study/execution_records.h"
#include "worklists/audit_trail.h"
#include "worklists/task_store.h"

namespace mmm::worklists {
namespace {

using Json = nlohmann::json;

// What the chain says about one task.
struct TaskTrail {
  bool opened = false;
  std::int64_t last_acceptance = 0;  // seq of the last accept/correct entry (0: none)
  std::optional<Json> accepted;      // its `after`, when it parses
};

std::map<std::string, TaskTrail> trails_of(const std::vector<AuditRow>& rows) {
  std::map<std::string, TaskTrail> trails;
  for (const AuditRow& row : rows) {
    TaskTrail& trail = trails[row.task_id];
    if (row.action == "open") trail.opened = true;
    if (row.action == "accept" || row.action == "correct") {
      trail.last_acceptance = row.seq;
      const Json after = parse_json_or_discarded(row.after_json);
      trail.accepted = after.is_discarded() ? std::nullopt : std::optional<Json>(after);
    }
  }
  return trails;
}

std::optional<workflow::ExecutionRecord> execution_by_id(workflow::Database& database,
                                                         const Task& task) {
  for (workflow::ExecutionRecord& record : workflow::executions_of(database, task.node)) {
    if (record.id == task.result_execution) return std::move(record);
  }
  return std::nullopt;
}

}  // namespace

std::vector<AuditProblem> cross_check_tasks(workflow::Database& database,
                                            const std::filesystem::path& study_dir) {
  std::vector<AuditProblem> problems;
  if (!tasks_table_exists(database)) return problems;
  const std::map<std::string, TaskTrail> trails = trails_of(read_audit_rows(database));
  for (const Task& task : all_tasks(database)) {
    const auto found = trails.find(task.id);
    if (found == trails.end() || !found->second.opened) {
      problems.push_back({AuditProblemKind::kTaskUnaudited, 0,
                          "task " + task.id + " (node '" + task.node +
                              "') is in the tasks table but no entry of the trail opened it: "
                              "entries were deleted or the task was added outside mmm"});
      continue;
    }
    if (task.state != TaskState::kAccepted) continue;
    const TaskTrail& trail = found->second;
    if (trail.last_acceptance == 0 || !trail.accepted || *trail.accepted != task.result) {
      problems.push_back(
          {AuditProblemKind::kValueMismatch, trail.last_acceptance,
           "the accepted values of task " + task.id + " differ from those " +
               (trail.last_acceptance == 0
                    ? std::string("of any entry (none accepted it)")
                    : "entry " + std::to_string(trail.last_acceptance) + " recorded") +
               ": the tasks table was edited"});
    }
    const std::optional<workflow::ExecutionRecord> result = execution_by_id(database, task);
    if (!result) {
      problems.push_back({AuditProblemKind::kValueMismatch, trail.last_acceptance,
                          "task " + task.id + "'s accepted result (execution " +
                              std::to_string(task.result_execution) +
                              ") is missing from the executions table"});
      continue;
    }
    for (const auto& [port, output] : result->outputs) {
      const std::filesystem::path blob =
          study_dir / "artifacts" / workflow::ArtifactStore::relative_path_of(output.hash);
      std::string actual;
      try {
        actual = hash::sha256_file_hex(blob);
      } catch (const IoError&) {
        actual = "(missing)";
      }
      if (actual != output.hash) {
        problems.push_back(
            {AuditProblemKind::kArtifactChanged, trail.last_acceptance,
             "output '" + port + "' of task " + task.id + "'s accepted result, artifact " +
                 output.hash.substr(0, 16) + "..., " +
                 (actual == "(missing)"
                      ? std::string("is missing")
                      : "now hashes to " + actual.substr(0, 16) + "...: it was edited in place")});
      }
    }
  }
  return problems;
}

}  // namespace mmm::worklists

#pragma once
// Rows of the executions and logs tables (study_database.h): what each node
// execution was (type, version, cache key and the parts it was made of), what
// it produced, how it ended, when, where and why it ran. The cache of a study
// is this table: a node's earlier result is reused when a 'done' execution
// with the same cache key exists and its artifacts are in the store.

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "workflow/node_context.h"
#include "workflow/port_type.h"
#include "workflow/store/sqlite.h"
#include "workflow/study/cache_key.h"

namespace mmm::workflow {

enum class ExecutionStatus {
  kRunning,      // started, not finished (a crash leaves these: see mark_interrupted)
  kDone,         // finished; outputs recorded
  kFailed,       // the node threw, or broke its contract; error recorded
  kInterrupted,  // the runner died while it ran
};
std::string_view execution_status_name(ExecutionStatus status);

struct OutputArtifact {
  PortType type = PortType::kFile;
  std::string hash;

  bool operator==(const OutputArtifact&) const = default;
};

struct ExecutionRecord {
  std::int64_t id = 0;
  std::int64_t run_id = 0;  // 0: not made by a run (a manual result)
  std::string node;
  std::string node_type;
  int version = 0;
  std::string cache_key;
  CacheKeyParts key_parts;
  std::map<std::string, OutputArtifact> outputs;
  ExecutionStatus status = ExecutionStatus::kRunning;
  bool manual = false;      // a person's result for a manual node
  std::string reason;       // why it ran ("first run", "parameter 'x' changed ...")
  std::string started_at;   // UTC
  std::string finished_at;  // UTC; empty while running
  double seconds = 0;       // wall-clock duration
  std::string error;        // kFailed: what went wrong
  std::string host;
  std::int64_t pid = 0;
  std::string submitted_by;  // manual results: the operator
};

struct LogLine {
  std::string time;  // UTC with milliseconds
  LogLevel level = LogLevel::kInfo;
  std::string message;
};
std::string_view log_level_name(LogLevel level);
// The level of a name log_level_name gives; kInfo for any other.
LogLevel log_level_from_name(std::string_view name);

// Inserts `record` (id ignored) and returns its id.
std::int64_t insert_execution(Database& database, const ExecutionRecord& record);

// Records the end of execution `id`: status, outputs, error, end time,
// duration, and its log lines.
void finish_execution(Database& database, std::int64_t id, const ExecutionRecord& record,
                      const std::vector<LogLine>& logs);

// The latest 'done' execution with this cache key (any node; for manual nodes
// only results of node `manual_node`). std::nullopt when there is none.
std::optional<ExecutionRecord> find_result(Database& database, const std::string& cache_key,
                                           const std::string* manual_node = nullptr);

// The latest execution of `node` (any status), and the latest 'done' one.
std::optional<ExecutionRecord> last_execution(Database& database, const std::string& node);
std::optional<ExecutionRecord> last_done_execution(Database& database, const std::string& node);

// Every execution of `node`, oldest first.
std::vector<ExecutionRecord> executions_of(Database& database, const std::string& node);

std::vector<LogLine> execution_logs(Database& database, std::int64_t id);

// Marks every 'running' execution 'interrupted' (called by a runner holding
// the study lock: nothing else can be running). Returns how many.
int mark_interrupted(Database& database);

// JSON of outputs: {"port": {"type": "Mesh", "hash": "..."}}.
nlohmann::json outputs_json(const std::map<std::string, OutputArtifact>& outputs);

}  // namespace mmm::workflow

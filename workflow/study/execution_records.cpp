#include "workflow/study/execution_records.h"

#include "core/errors.h"

namespace mmm::workflow {
namespace {

constexpr const char* kColumns =
    "id, run_id, node, node_type, version, cache_key, key_json, outputs_json, status, manual, "
    "reason, started_at, finished_at, seconds, error, host, pid, submitted_by";

ExecutionStatus status_from_name(const std::string& name) {
  for (const ExecutionStatus status : {ExecutionStatus::kRunning, ExecutionStatus::kDone,
                                       ExecutionStatus::kFailed, ExecutionStatus::kInterrupted}) {
    if (execution_status_name(status) == name) return status;
  }
  throw InvalidInputError("unknown execution status '" + name + "' in the study database");
}

std::map<std::string, OutputArtifact> outputs_from_json(const nlohmann::json& json) {
  std::map<std::string, OutputArtifact> outputs;
  for (const auto& [port, value] : json.items()) {
    const std::optional<PortType> type = port_type_from_name(value.at("type").get<std::string>());
    if (!type) throw InvalidInputError("unknown port type in the study database: " + value.dump());
    outputs[port] = {*type, value.at("hash").get<std::string>()};
  }
  return outputs;
}

ExecutionRecord read_row(const Statement& row) {
  ExecutionRecord record;
  record.id = row.column_int64(0);
  record.run_id = row.column_int64(1);
  record.node = row.column_text(2);
  record.node_type = row.column_text(3);
  record.version = static_cast<int>(row.column_int64(4));
  record.cache_key = row.column_text(5);
  record.key_parts = cache_key_parts_from_json(nlohmann::json::parse(row.column_text(6)));
  record.outputs = outputs_from_json(nlohmann::json::parse(row.column_text(7)));
  record.status = status_from_name(row.column_text(8));
  record.manual = row.column_int64(9) != 0;
  record.reason = row.column_text(10);
  record.started_at = row.column_text(11);
  record.finished_at = row.column_text(12);
  record.seconds = row.column_double(13);
  record.error = row.column_text(14);
  record.host = row.column_text(15);
  record.pid = row.column_int64(16);
  record.submitted_by = row.column_text(17);
  return record;
}

std::optional<ExecutionRecord> first_row(Statement& select) {
  if (!select.step()) return std::nullopt;
  return read_row(select);
}

}  // namespace

std::string_view execution_status_name(ExecutionStatus status) {
  switch (status) {
    case ExecutionStatus::kRunning:
      return "running";
    case ExecutionStatus::kDone:
      return "done";
    case ExecutionStatus::kFailed:
      return "failed";
    case ExecutionStatus::kInterrupted:
      return "interrupted";
  }
  return "unknown";
}

LogLevel log_level_from_name(std::string_view name) {
  for (const LogLevel level :
       {LogLevel::kDebug, LogLevel::kInfo, LogLevel::kWarning, LogLevel::kError}) {
    if (log_level_name(level) == name) return level;
  }
  return LogLevel::kInfo;
}

std::string_view log_level_name(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "debug";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kWarning:
      return "warning";
    case LogLevel::kError:
      return "error";
  }
  return "info";
}

nlohmann::json outputs_json(const std::map<std::string, OutputArtifact>& outputs) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [port, artifact] : outputs) {
    json[port] = {{"type", std::string(port_type_name(artifact.type))}, {"hash", artifact.hash}};
  }
  return json;
}

std::int64_t insert_execution(Database& database, const ExecutionRecord& record) {
  database
      .prepare(
          "INSERT INTO executions(run_id, node, node_type, version, cache_key, key_json, "
          "outputs_json, status, manual, reason, started_at, finished_at, seconds, error, host, "
          "pid, submitted_by) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)")
      .bind_int64(1, record.run_id)
      .bind_text(2, record.node)
      .bind_text(3, record.node_type)
      .bind_int64(4, record.version)
      .bind_text(5, record.cache_key)
      .bind_text(6, cache_key_json(record.key_parts).dump())
      .bind_text(7, outputs_json(record.outputs).dump())
      .bind_text(8, execution_status_name(record.status))
      .bind_int64(9, record.manual ? 1 : 0)
      .bind_text(10, record.reason)
      .bind_text(11, record.started_at)
      .bind_text(12, record.finished_at)
      .bind_double(13, record.seconds)
      .bind_text(14, record.error)
      .bind_text(15, record.host)
      .bind_int64(16, record.pid)
      .bind_text(17, record.submitted_by)
      .step();
  return database.last_insert_rowid();
}

void finish_execution(Database& database, std::int64_t id, const ExecutionRecord& record,
                      const std::vector<LogLine>& logs) {
  database
      .prepare(
          "UPDATE executions SET outputs_json = ?, status = ?, finished_at = ?, seconds = ?, "
          "error = ? WHERE id = ?")
      .bind_text(1, outputs_json(record.outputs).dump())
      .bind_text(2, execution_status_name(record.status))
      .bind_text(3, record.finished_at)
      .bind_double(4, record.seconds)
      .bind_text(5, record.error)
      .bind_int64(6, id)
      .step();
  if (logs.empty()) return;
  Statement insert =
      database.prepare("INSERT INTO logs(execution_id, time, level, message) VALUES (?, ?, ?, ?)");
  for (const LogLine& line : logs) {
    insert.reset();
    insert.bind_int64(1, id)
        .bind_text(2, line.time)
        .bind_text(3, log_level_name(line.level))
        .bind_text(4, line.message);
    insert.step();
  }
}

std::optional<ExecutionRecord> find_result(Database& database, const std::string& cache_key,
                                           const std::string* manual_node) {
  std::string sql = std::string("SELECT ") + kColumns +
                    " FROM executions WHERE cache_key = ? AND status = 'done'";
  sql += manual_node != nullptr ? " AND manual = 1 AND node = ?" : " AND manual = 0";
  sql += " ORDER BY id DESC LIMIT 1";
  Statement select = database.prepare(sql);
  select.bind_text(1, cache_key);
  if (manual_node != nullptr) select.bind_text(2, *manual_node);
  return first_row(select);
}

std::optional<ExecutionRecord> last_execution(Database& database, const std::string& node) {
  Statement select = database.prepare(std::string("SELECT ") + kColumns +
                                      " FROM executions WHERE node = ? ORDER BY id DESC LIMIT 1");
  select.bind_text(1, node);
  return first_row(select);
}

std::optional<ExecutionRecord> last_done_execution(Database& database, const std::string& node) {
  Statement select = database.prepare(
      std::string("SELECT ") + kColumns +
      " FROM executions WHERE node = ? AND status = 'done' ORDER BY id DESC LIMIT 1");
  select.bind_text(1, node);
  return first_row(select);
}

std::vector<ExecutionRecord> executions_of(Database& database, const std::string& node) {
  Statement select = database.prepare(std::string("SELECT ") + kColumns +
                                      " FROM executions WHERE node = ? ORDER BY id");
  select.bind_text(1, node);
  std::vector<ExecutionRecord> records;
  while (select.step()) records.push_back(read_row(select));
  return records;
}

std::vector<LogLine> execution_logs(Database& database, std::int64_t id) {
  Statement select = database.prepare(
      "SELECT time, level, message FROM logs WHERE execution_id = ? ORDER BY rowid");
  select.bind_int64(1, id);
  std::vector<LogLine> lines;
  while (select.step()) {
    lines.push_back(
        {select.column_text(0), log_level_from_name(select.column_text(1)), select.column_text(2)});
  }
  return lines;
}

int mark_interrupted(Database& database) {
  database.exec(
      "UPDATE executions SET status = 'interrupted', error = 'the runner stopped while the node "
      "ran (crash, kill or power loss); it runs again' WHERE status = 'running'");
  return database.changes();
}

}  // namespace mmm::workflow

#include "worklists/task_store.h"

#include <cstdio>
#include <random>

#include "core/errors.h"

namespace mmm::worklists {
namespace {

using workflow::Database;
using workflow::Statement;
using Json = nlohmann::json;

constexpr const char* kTaskColumns =
    "id, node, node_type, cache_key, key_json, state, assignee, created_at, updated_at, "
    "request_json, submission_json, result_json, rejection_json, result_execution, revision, "
    "submitted_by, pending_json";

Task read_row(Statement& row) {
  Task task;
  task.id = row.column_text(0);
  task.node = row.column_text(1);
  task.node_type = row.column_text(2);
  task.cache_key = row.column_text(3);
  task.key_parts = workflow::cache_key_parts_from_json(Json::parse(row.column_text(4)));
  const auto state = task_state_from_name(row.column_text(5));
  if (!state) {
    throw IoError(std::string("tasks"), "task " + task.id + " has an unknown state '" +
                                            row.column_text(5) + "' (written by a newer mmm?)");
  }
  task.state = *state;
  task.assignee = row.column_text(6);
  task.created_at = row.column_text(7);
  task.updated_at = row.column_text(8);
  task.request = Json::parse(row.column_text(9));
  task.submission = Json::parse(row.column_text(10));
  task.result = Json::parse(row.column_text(11));
  task.rejection_reasons = Json::parse(row.column_text(12)).get<std::vector<std::string>>();
  task.result_execution = row.column_int64(13);
  task.revision = static_cast<int>(row.column_int64(14));
  task.submitted_by = row.column_text(15);
  task.pending_correction = Json::parse(row.column_text(16));
  return task;
}

// Binds the fields after the id, from parameter 2 on.
void bind_fields(Statement& statement, const Task& task) {
  statement.bind_text(2, task.node)
      .bind_text(3, task.node_type)
      .bind_text(4, task.cache_key)
      .bind_text(5, workflow::cache_key_json(task.key_parts).dump())
      .bind_text(6, task_state_name(task.state))
      .bind_text(7, task.assignee)
      .bind_text(8, task.created_at)
      .bind_text(9, task.updated_at)
      .bind_text(10, task.request.dump())
      .bind_text(11, task.submission.dump())
      .bind_text(12, task.result.dump())
      .bind_text(13, Json(task.rejection_reasons).dump())
      .bind_int64(14, task.result_execution)
      .bind_int64(15, task.revision)
      .bind_text(16, task.submitted_by)
      .bind_text(17, task.pending_correction.dump());
}

std::vector<Task> select_tasks(Database& database, const std::string& where,
                               const std::string& value) {
  Statement select = database.prepare(std::string("SELECT ") + kTaskColumns + " FROM tasks" +
                                      where + " ORDER BY created_at, id");
  if (!where.empty()) select.bind_text(1, value);
  std::vector<Task> tasks;
  while (select.step()) tasks.push_back(read_row(select));
  return tasks;
}

}  // namespace

void prepare_task_tables(Database& database) {
  database.exec(R"sql(
CREATE TABLE IF NOT EXISTS tasks(
  id TEXT PRIMARY KEY,
  node TEXT NOT NULL,
  node_type TEXT NOT NULL,
  cache_key TEXT NOT NULL,
  key_json TEXT NOT NULL,
  state TEXT NOT NULL,
  assignee TEXT NOT NULL DEFAULT '',
  created_at TEXT NOT NULL,
  updated_at TEXT NOT NULL,
  request_json TEXT NOT NULL,
  submission_json TEXT NOT NULL DEFAULT 'null',
  result_json TEXT NOT NULL DEFAULT 'null',
  rejection_json TEXT NOT NULL DEFAULT '[]',
  result_execution INTEGER NOT NULL DEFAULT 0,
  revision INTEGER NOT NULL DEFAULT 0);
CREATE INDEX IF NOT EXISTS tasks_by_node ON tasks(node, created_at);
)sql");
  // Studies created before review covered corrections: add the columns.
  bool current = false;
  {
    Statement has_column =
        database.prepare("SELECT 1 FROM pragma_table_info('tasks') WHERE name = 'submitted_by'");
    current = has_column.step();
  }
  if (!current) {
    database.exec(
        "ALTER TABLE tasks ADD COLUMN submitted_by TEXT NOT NULL DEFAULT '';"
        "ALTER TABLE tasks ADD COLUMN pending_json TEXT NOT NULL DEFAULT 'null';");
  }
}

bool tasks_table_exists(Database& database) {
  Statement table =
      database.prepare("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'tasks'");
  return table.step();
}

std::string new_task_id() {
  std::random_device source;
  std::uniform_int_distribution<int> nibble(0, 15);
  std::string id;
  for (int i = 0; i < 10; ++i) id += "0123456789abcdef"[nibble(source)];
  return id;
}

void insert_task(Database& database, const Task& task) {
  if (find_task(database, task.id)) {
    throw InvalidInputError("task id " + task.id + " is already used in " +
                            database.path().string());
  }
  Statement insert =
      database.prepare(std::string("INSERT INTO tasks(") + kTaskColumns +
                       ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  insert.bind_text(1, task.id);
  bind_fields(insert, task);
  insert.step();
}

bool update_task(Database& database, const Task& task) {
  Statement update = database.prepare(
      "UPDATE tasks SET node = ?2, node_type = ?3, cache_key = ?4, key_json = ?5, state = ?6, "
      "assignee = ?7, created_at = ?8, updated_at = ?9, request_json = ?10, "
      "submission_json = ?11, result_json = ?12, rejection_json = ?13, result_execution = ?14, "
      "revision = ?15, submitted_by = ?16, pending_json = ?17 WHERE id = ?1 AND revision = ?18");
  update.bind_text(1, task.id);
  bind_fields(update, task);
  update.bind_int64(18, task.revision - 1);
  update.step();
  return database.changes() == 1;
}

std::optional<Task> find_task(Database& database, const std::string& id) {
  std::vector<Task> tasks = select_tasks(database, " WHERE id = ?", id);
  if (tasks.empty()) return std::nullopt;
  return std::move(tasks.front());
}

std::vector<Task> tasks_of_node(Database& database, const std::string& node) {
  return select_tasks(database, " WHERE node = ?", node);
}

std::vector<Task> all_tasks(Database& database) { return select_tasks(database, "", ""); }

}  // namespace mmm::worklists

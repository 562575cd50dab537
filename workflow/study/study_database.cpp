#include "workflow/study/study_database.h"

#include <optional>
#include <string>

namespace mmm::workflow {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS meta(
  key TEXT PRIMARY KEY,
  value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS inputs(
  name TEXT PRIMARY KEY,
  type TEXT NOT NULL,
  hash TEXT NOT NULL,
  is_file INTEGER NOT NULL,
  given TEXT NOT NULL,
  source_size INTEGER NOT NULL,
  source_mtime_ns INTEGER NOT NULL,
  updated_at TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS param_overrides(
  node TEXT NOT NULL,
  param TEXT NOT NULL,
  value_json TEXT NOT NULL,
  set_at TEXT NOT NULL,
  PRIMARY KEY(node, param));
CREATE TABLE IF NOT EXISTS runs(
  id INTEGER PRIMARY KEY,
  started_at TEXT NOT NULL,
  finished_at TEXT,
  status TEXT NOT NULL,
  host TEXT NOT NULL,
  pid INTEGER NOT NULL,
  mmm_version TEXT NOT NULL,
  git_revision TEXT NOT NULL,
  workflow_hash TEXT NOT NULL,
  jobs INTEGER NOT NULL,
  executed INTEGER NOT NULL DEFAULT 0,
  cached INTEGER NOT NULL DEFAULT 0,
  failed INTEGER NOT NULL DEFAULT 0,
  waiting INTEGER NOT NULL DEFAULT 0);
CREATE TABLE IF NOT EXISTS executions(
  id INTEGER PRIMARY KEY,
  run_id INTEGER,
  node TEXT NOT NULL,
  node_type TEXT NOT NULL,
  version INTEGER NOT NULL,
  cache_key TEXT NOT NULL,
  key_json TEXT NOT NULL,
  outputs_json TEXT NOT NULL DEFAULT '{}',
  status TEXT NOT NULL,
  manual INTEGER NOT NULL DEFAULT 0,
  reason TEXT NOT NULL DEFAULT '',
  started_at TEXT NOT NULL,
  finished_at TEXT,
  seconds REAL,
  error TEXT NOT NULL DEFAULT '',
  host TEXT NOT NULL,
  pid INTEGER NOT NULL,
  submitted_by TEXT NOT NULL DEFAULT '');
CREATE INDEX IF NOT EXISTS executions_by_key ON executions(cache_key, status);
CREATE INDEX IF NOT EXISTS executions_by_node ON executions(node, id);
CREATE TABLE IF NOT EXISTS logs(
  execution_id INTEGER NOT NULL REFERENCES executions(id) ON DELETE CASCADE,
  time TEXT NOT NULL,
  level TEXT NOT NULL,
  message TEXT NOT NULL);
CREATE INDEX IF NOT EXISTS logs_by_execution ON logs(execution_id);
CREATE TABLE IF NOT EXISTS crashes(
  id INTEGER PRIMARY KEY,
  node TEXT NOT NULL,
  cache_key TEXT NOT NULL,
  signal INTEGER NOT NULL,
  noticed_at TEXT NOT NULL);
CREATE INDEX IF NOT EXISTS crashes_by_key ON crashes(cache_key, node);
CREATE TABLE IF NOT EXISTS exports(
  name TEXT PRIMARY KEY,
  hash TEXT NOT NULL,
  file TEXT NOT NULL,
  exported_at TEXT NOT NULL);
)sql";

}  // namespace

void prepare_study_database(Database& database) {
  Transaction transaction(database);
  database.exec(kSchema);
  std::optional<std::string> format;
  {
    Statement read = database.prepare("SELECT value FROM meta WHERE key = 'format'");
    if (read.step()) format = read.column_text(0);
  }
  if (format) {
    if (*format != std::to_string(kStudyFormat)) {
      throw IoError(database.path(), "study format " + *format +
                                         " is not supported (this mmm reads format " +
                                         std::to_string(kStudyFormat) +
                                         "); open the study with the mmm version that created it");
    }
  } else {
    database.prepare("INSERT INTO meta(key, value) VALUES ('format', ?)")
        .bind_text(1, std::to_string(kStudyFormat))
        .step();
  }
  transaction.commit();
}

}  // namespace mmm::workflow

#include "worklists/audit_trail.h"

#include <sqlite3.h>

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "workflow/host_and_time.h"

namespace mmm::worklists {
namespace {

using workflow::Statement;

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS meta(
  key TEXT PRIMARY KEY,
  value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS audit(
  seq INTEGER PRIMARY KEY,
  time TEXT NOT NULL,
  operator_name TEXT NOT NULL,
  task_id TEXT NOT NULL,
  action TEXT NOT NULL,
  before_json TEXT NOT NULL,
  after_json TEXT NOT NULL,
  reason TEXT NOT NULL,
  mmm_version TEXT NOT NULL,
  images_json TEXT NOT NULL,
  prev_hash TEXT NOT NULL,
  hash TEXT NOT NULL);
CREATE TRIGGER IF NOT EXISTS audit_no_update BEFORE UPDATE ON audit
BEGIN SELECT RAISE(ABORT, 'the audit trail is append-only: entries cannot be changed'); END;
CREATE TRIGGER IF NOT EXISTS audit_no_delete BEFORE DELETE ON audit
BEGIN SELECT RAISE(ABORT, 'the audit trail is append-only: entries cannot be deleted'); END;
)sql";

constexpr const char* kAuditColumns =
    "seq, time, operator_name, task_id, action, before_json, after_json, reason, mmm_version, "
    "images_json, prev_hash, hash";

constexpr const char* kCheckpointFormat = "mmm-audit-checkpoint-v1";

bool in_transaction(const Database& database) {
  return sqlite3_get_autocommit(database.handle()) == 0;
}

// Compact JSON text of `value`; InvalidInputError naming `field` when it holds
// text that is not UTF-8.
std::string json_text(const nlohmann::json& value, std::string_view field) {
  try {
    return value.dump();
  } catch (const nlohmann::json::exception& error) {
    throw InvalidInputError("audit entry field '" + std::string(field) +
                            "': cannot be written as JSON (" + error.what() +
                            "); hint: text must be UTF-8");
  }
}

void require_utf8(const std::string& text, std::string_view field) {
  (void)json_text(nlohmann::json(text), field);
}

void require_non_empty(const std::string& text, std::string_view field) {
  if (text.empty()) {
    throw InvalidInputError("audit entry field '" + std::string(field) +
                            "' is empty; hint: every entry names its " + std::string(field));
  }
}

void validate(const AuditEntry& entry) {
  if (std::ranges::find(kAuditActions, std::string_view(entry.action)) == kAuditActions.end()) {
    std::string names;
    for (const std::string_view name : kAuditActions)
      names += (names.empty() ? "" : ", ") + std::string(name);
    throw InvalidInputError("audit entry field 'action': unknown action '" + entry.action +
                            "'; hint: one of " + names);
  }
  require_non_empty(entry.operator_name, "operator_name");
  require_non_empty(entry.task_id, "task_id");
  require_non_empty(entry.mmm_version, "mmm_version");
  if (entry.action == "reject" && entry.reason.empty()) {
    throw InvalidInputError(
        "audit entry field 'reason' is empty for action 'reject'; hint: a rejection records "
        "why, for the operator who corrects it");
  }
  if (!entry.images.is_array() && !entry.images.is_object() && !entry.images.is_null()) {
    throw InvalidInputError(std::string("audit entry field 'images': expected a JSON array or ") +
                            "object of image content hashes (or null), got " +
                            entry.images.type_name());
  }
  require_utf8(entry.operator_name, "operator_name");
  require_utf8(entry.task_id, "task_id");
  require_utf8(entry.reason, "reason");
  require_utf8(entry.mmm_version, "mmm_version");
}

std::string head_json(const AuditHead& head) {
  return nlohmann::json{{"seq", head.seq}, {"hash", head.hash}}.dump();
}

// {"seq": n >= 0, "hash": "<64 hex>"} -> AuditHead; an empty string when it is
// not, else the problem.
std::string parse_head(const nlohmann::json& json, AuditHead& head) {
  if (!json.is_object()) return std::string("expected a JSON object, got ") + json.type_name();
  const auto seq = json.find("seq");
  if (seq == json.end() || !seq->is_number_integer() || seq->get<std::int64_t>() < 0) {
    return "'seq' is missing or not a non-negative integer";
  }
  const auto hash = json.find("hash");
  if (hash == json.end() || !hash->is_string() || !is_audit_hash(hash->get<std::string>())) {
    return "'hash' is missing or not 64 lowercase hexadecimal characters";
  }
  head.seq = seq->get<std::int64_t>();
  head.hash = hash->get<std::string>();
  return {};
}

AuditRow row_of(const Statement& select) {
  AuditRow row;
  row.seq = select.column_int64(0);
  row.time = select.column_text(1);
  row.operator_name = select.column_text(2);
  row.task_id = select.column_text(3);
  row.action = select.column_text(4);
  row.before_json = select.column_text(5);
  row.after_json = select.column_text(6);
  row.reason = select.column_text(7);
  row.mmm_version = select.column_text(8);
  row.images_json = select.column_text(9);
  row.prev_hash = select.column_text(10);
  row.hash = select.column_text(11);
  return row;
}

nlohmann::json parse_column(const Database& database, const AuditRow& row, const std::string& text,
                            std::string_view column) {
  try {
    return parse_json(text);
  } catch (const nlohmann::json::exception& error) {
    throw IoError(database.path(), "audit entry seq " + std::to_string(row.seq) + ": column '" +
                                       std::string(column) + "' is not JSON (" + error.what() +
                                       "); hint: the trail was edited outside mmm, run the "
                                       "audit verification");
  }
}

}  // namespace

void prepare_audit_tables(Database& database) { database.exec(kSchema); }

void open_audit_trail(Database& database, const std::filesystem::path& study_dir) {
  prepare_audit_tables(database);
  if (audit_database_head(database).seq == 0 &&
      !std::filesystem::exists(audit_checkpoint_path(study_dir))) {
    write_audit_checkpoint(study_dir, database);
  }
}

void insert_audit_row(Database& database, const AuditRow& row) {
  database
      .prepare(std::string("INSERT INTO audit(") + kAuditColumns +
               ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)")
      .bind_int64(1, row.seq)
      .bind_text(2, row.time)
      .bind_text(3, row.operator_name)
      .bind_text(4, row.task_id)
      .bind_text(5, row.action)
      .bind_text(6, row.before_json)
      .bind_text(7, row.after_json)
      .bind_text(8, row.reason)
      .bind_text(9, row.mmm_version)
      .bind_text(10, row.images_json)
      .bind_text(11, row.prev_hash)
      .bind_text(12, row.hash)
      .step();
}

AuditEntry append_audit_entry(Database& database, AuditEntry entry) {
  if (!in_transaction(database)) {
    throw std::logic_error(database.path().string() +
                           ": append_audit_entry outside a transaction; hint: open a "
                           "workflow::Transaction, record the task change and the entry in it, "
                           "commit, then call write_audit_checkpoint");
  }
  validate(entry);
  const AuditHead head = audit_database_head(database);
  AuditRow row;
  row.seq = head.seq + 1;
  row.prev_hash = head.hash;
  row.time = workflow::utc_now_precise();
  row.operator_name = entry.operator_name;
  row.task_id = entry.task_id;
  row.action = entry.action;
  row.before_json = json_text(entry.before, "before");
  row.after_json = json_text(entry.after, "after");
  row.reason = entry.reason;
  row.mmm_version = entry.mmm_version;
  row.images_json = json_text(entry.images, "images");
  row.hash = audit_row_hash(row);

  insert_audit_row(database, row);
  database.prepare("INSERT OR REPLACE INTO meta(key, value) VALUES ('audit_head', ?)")
      .bind_text(1, head_json({row.seq, row.hash}))
      .step();

  entry.seq = row.seq;
  entry.time = std::move(row.time);
  entry.prev_hash = std::move(row.prev_hash);
  entry.hash = std::move(row.hash);
  return entry;
}

std::filesystem::path audit_checkpoint_path(const std::filesystem::path& study_dir) {
  return study_dir / "audit.checkpoint";
}

void write_audit_checkpoint(const std::filesystem::path& study_dir, Database& database) {
  if (in_transaction(database)) {
    throw std::logic_error(database.path().string() +
                           ": write_audit_checkpoint inside a transaction; hint: commit first, "
                           "a rolled-back entry must never reach the checkpoint");
  }
  const std::filesystem::path path = audit_checkpoint_path(study_dir);
  // The file first, then the database: entries are committed before their
  // checkpoint is written, so an honest database is never behind what was read.
  std::optional<AuditHead> existing;
  try {
    existing = read_audit_checkpoint(study_dir);
  } catch (const IoError& error) {
    throw IoError(path, std::string("the audit checkpoint is damaged (") + error.what() +
                            "); it is left as it is; hint: run the audit verification");
  }
  const AuditHead head = audit_database_head(database);
  if (!existing && head.seq > 1) {
    throw IoError(path, "the audit checkpoint is missing although the trail has " +
                            std::to_string(head.seq) +
                            " entries; hint: run the audit verification (it may have been "
                            "deleted)");
  }
  if (existing && existing->seq > 0) {
    if (existing->seq > head.seq) {
      throw IoError(path, "the audit checkpoint records seq " + std::to_string(existing->seq) +
                              " but the trail ends at seq " + std::to_string(head.seq) +
                              "; it is left as it is; hint: run the audit verification (entries "
                              "may have been deleted)");
    }
    Statement at = database.prepare("SELECT hash FROM audit WHERE seq = ?");
    at.bind_int64(1, existing->seq);
    if (!at.step() || at.column_text(0) != existing->hash) {
      throw IoError(path, "the audit checkpoint's entry seq " + std::to_string(existing->seq) +
                              " is not the one in the database; it is left as it is; hint: run "
                              "the audit verification (the trail may have been rewritten)");
    }
  }
  const nlohmann::json checkpoint = {{"format", kCheckpointFormat},
                                     {"seq", head.seq},
                                     {"hash", head.hash},
                                     {"written_at", workflow::utc_now_precise()}};
  write_file_atomically(path, checkpoint.dump(2) + "\n", "the audit checkpoint");
}

std::vector<AuditRow> read_audit_rows(Database& database) {
  std::vector<AuditRow> rows;
  Statement select =
      database.prepare(std::string("SELECT ") + kAuditColumns + " FROM audit ORDER BY seq");
  while (select.step()) rows.push_back(row_of(select));
  return rows;
}

std::vector<AuditEntry> read_audit(Database& database) {
  std::vector<AuditEntry> entries;
  for (AuditRow& row : read_audit_rows(database)) {
    AuditEntry entry;
    entry.before = parse_column(database, row, row.before_json, "before_json");
    entry.after = parse_column(database, row, row.after_json, "after_json");
    entry.images = parse_column(database, row, row.images_json, "images_json");
    entry.seq = row.seq;
    entry.time = std::move(row.time);
    entry.operator_name = std::move(row.operator_name);
    entry.task_id = std::move(row.task_id);
    entry.action = std::move(row.action);
    entry.reason = std::move(row.reason);
    entry.mmm_version = std::move(row.mmm_version);
    entry.prev_hash = std::move(row.prev_hash);
    entry.hash = std::move(row.hash);
    entries.push_back(std::move(entry));
  }
  return entries;
}

AuditHead audit_database_head(Database& database) {
  Statement last = database.prepare("SELECT seq, hash FROM audit ORDER BY seq DESC LIMIT 1");
  if (!last.step()) return {};
  return {last.column_int64(0), last.column_text(1)};
}

std::optional<std::string> last_operator_of(Database& database, const std::string& task_id,
                                            std::string_view action) {
  Statement last = database.prepare(
      "SELECT operator_name FROM audit WHERE task_id = ? AND action = ? ORDER BY seq DESC LIMIT 1");
  last.bind_text(1, task_id).bind_text(2, action);
  if (!last.step()) return std::nullopt;
  return last.column_text(0);
}

std::optional<AuditHead> read_audit_meta_head(Database& database) {
  Statement read = database.prepare("SELECT value FROM meta WHERE key = 'audit_head'");
  if (!read.step()) return std::nullopt;
  const std::string text = read.column_text(0);
  AuditHead head;
  std::string problem;
  try {
    problem = parse_head(parse_json(text), head);
  } catch (const nlohmann::json::exception& error) {
    problem = std::string("not JSON (") + error.what() + ")";
  }
  if (!problem.empty()) {
    throw IoError(database.path(), "meta 'audit_head' = '" + text + "': " + problem +
                                       "; hint: it is written only by append_audit_entry, so it "
                                       "was edited");
  }
  return head;
}

std::optional<AuditHead> read_audit_checkpoint(const std::filesystem::path& study_dir) {
  const std::filesystem::path path = audit_checkpoint_path(study_dir);
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) return std::nullopt;
  if (status.type() != std::filesystem::file_type::regular) {
    throw IoError(path,
                  "not a regular file; hint: the checkpoint is a small JSON file written "
                  "by mmm");
  }
  const std::string text = read_file_bytes(path, std::filesystem::file_size(path));
  AuditHead head;
  std::string problem;
  try {
    const nlohmann::json json = parse_json(text);
    const auto format = json.is_object() ? json.find("format") : json.end();
    if (!json.is_object() || format == json.end() || *format != kCheckpointFormat) {
      problem = std::string("'format' is not '") + kCheckpointFormat + "'";
    } else {
      problem = parse_head(json, head);
    }
  } catch (const nlohmann::json::exception& e) {
    problem = std::string("not JSON (") + e.what() + ")";
  }
  if (!problem.empty()) {
    throw IoError(path, "not an audit checkpoint: " + problem +
                            "; hint: the file is written only by mmm, so it was edited or damaged");
  }
  return head;
}

}  // namespace mmm::worklists

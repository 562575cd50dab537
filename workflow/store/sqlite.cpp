#include "workflow/store/sqlite.h"

#include <sqlite3.h>

#include <cstdint>
#include <utility>

namespace mmm::workflow {
namespace {

// Longest SQL excerpt quoted in an error message (characters).
constexpr std::size_t kSqlExcerpt = 160;

// SQLITE_TRANSIENT without the old-style cast of its macro: SQLite copies the
// bound text or blob before the bind call returns.
const sqlite3_destructor_type kTransient =
    reinterpret_cast<sqlite3_destructor_type>(static_cast<std::intptr_t>(-1));  // NOLINT

// `sql` on one line, whitespace runs collapsed, cut at kSqlExcerpt characters.
std::string excerpt(std::string_view sql) {
  std::string out;
  bool space = false;
  for (const char c : sql) {
    if (c == ' ' || c == '\n' || c == '\t' || c == '\r') {
      space = !out.empty();
      continue;
    }
    if (space) out.push_back(' ');
    space = false;
    out.push_back(c);
    if (out.size() >= kSqlExcerpt) return out + "...";
  }
  return out;
}

std::string hint_for(int code) {
  switch (code & 0xff) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      return "; another connection holds the lock (is another runner using this study?)";
    case SQLITE_FULL:
      return "; the disk is full";
    case SQLITE_READONLY:
    case SQLITE_PERM:
    case SQLITE_CANTOPEN:
      return "; check that the path is a writable file in an existing, writable folder";
    case SQLITE_NOTADB:
    case SQLITE_CORRUPT:
      return "; the file is not an intact SQLite database";
    default:
      return "";
  }
}

std::filesystem::path filename_of(sqlite3* db) {
  const char* name = sqlite3_db_filename(db, "main");
  return name == nullptr ? std::filesystem::path() : std::filesystem::path(name);
}

// The SqliteError for result `code` of a call on `db` concerning `sql`.
SqliteError make_error(sqlite3* db, const std::filesystem::path& path, int code,
                       std::string_view what, std::string_view sql) {
  std::string problem(what);
  if (!sql.empty()) problem += " SQL '" + excerpt(sql) + "'";
  problem += ": ";
  problem += db == nullptr ? sqlite3_errstr(code) : sqlite3_errmsg(db);
  problem += " (SQLite code " + std::to_string(code) + ")" + hint_for(code);
  return {path, problem, code};
}

[[noreturn]] void fail(sqlite3* db, const std::filesystem::path& path, int code,
                       std::string_view what, std::string_view sql) {
  throw make_error(db, path, code, what, sql);
}

void exec_on(sqlite3* db, const std::filesystem::path& path, std::string_view sql) {
  const std::string text(sql);
  const int code = sqlite3_exec(db, text.c_str(), nullptr, nullptr, nullptr);
  if (code != SQLITE_OK) fail(db, path, code, "cannot run", sql);
}

}  // namespace

// --- Database ---------------------------------------------------------------

Database::Database(std::filesystem::path path, const DatabaseOptions& options)
    : path_(std::move(path)) {
  constexpr int kFlags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX;
  const int code = sqlite3_open_v2(path_.c_str(), &db_, kFlags, nullptr);
  if (code != SQLITE_OK) {
    const std::string message = db_ == nullptr ? sqlite3_errstr(code) : sqlite3_errmsg(db_);
    close();
    throw SqliteError(path_,
                      "cannot open database: " + message + " (SQLite code " + std::to_string(code) +
                          ")" + hint_for(code),
                      code);
  }
  try {
    sqlite3_extended_result_codes(db_, 1);
    sqlite3_busy_timeout(db_, static_cast<int>(options.busy_timeout.count()));
    // Switching to WAL is persistent in the file; the pragma answers the mode
    // in force, which stays "delete" where WAL is impossible (no shared memory).
    {
      Statement journal(*this, "PRAGMA journal_mode=WAL");
      const std::string mode = journal.step() ? journal.column_text(0) : std::string();
      if (mode != "wal") {
        throw SqliteError(path_,
                          "cannot enable the WAL journal (journal_mode is '" + mode +
                              "'); keep the study on a local file system",
                          SQLITE_ERROR);
      }
    }
    exec("PRAGMA synchronous=FULL; PRAGMA foreign_keys=ON");
  } catch (...) {
    close();
    throw;
  }
}

Database::~Database() { close(); }

Database::Database(Database&& other) noexcept
    : path_(std::move(other.path_)), db_(std::exchange(other.db_, nullptr)) {}

Database& Database::operator=(Database&& other) noexcept {
  if (this != &other) {
    close();
    path_ = std::move(other.path_);
    db_ = std::exchange(other.db_, nullptr);
  }
  return *this;
}

void Database::close() noexcept {
  // close_v2 defers the close until the last statement is finalized.
  if (db_ != nullptr) sqlite3_close_v2(db_);
  db_ = nullptr;
}

void Database::exec(std::string_view sql) { exec_on(db_, path_, sql); }

Statement Database::prepare(std::string_view sql) { return {*this, sql}; }

std::int64_t Database::last_insert_rowid() const { return sqlite3_last_insert_rowid(db_); }

int Database::changes() const { return sqlite3_changes(db_); }

// --- Statement --------------------------------------------------------------

Statement::Statement(Database& database, std::string_view sql) {
  sqlite3* db = database.handle();
  const char* tail = nullptr;
  int code = sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &statement_, &tail);
  if (code != SQLITE_OK) fail(db, database.path(), code, "cannot prepare", sql);
  if (statement_ == nullptr) {
    throw SqliteError(database.path(), "cannot prepare SQL '" + excerpt(sql) + "': no statement",
                      SQLITE_MISUSE);
  }
  // A second statement would be silently ignored: refuse it.
  const auto used = static_cast<std::size_t>(tail - sql.data());
  const std::string_view rest = sql.substr(used);
  if (rest.find_first_not_of(" \t\r\n;") != std::string_view::npos) {
    sqlite3_stmt* next = nullptr;
    code = sqlite3_prepare_v2(db, rest.data(), static_cast<int>(rest.size()), &next, nullptr);
    sqlite3_finalize(next);
    if (code != SQLITE_OK || next != nullptr) {
      sqlite3_finalize(statement_);
      statement_ = nullptr;
      throw SqliteError(database.path(),
                        "cannot prepare SQL '" + excerpt(sql) +
                            "': it holds more than one statement; use Database::exec or "
                            "prepare them one by one",
                        SQLITE_MISUSE);
    }
  }
}

Statement::~Statement() { sqlite3_finalize(statement_); }

Statement::Statement(Statement&& other) noexcept
    : statement_(std::exchange(other.statement_, nullptr)) {}

Statement& Statement::operator=(Statement&& other) noexcept {
  if (this != &other) {
    sqlite3_finalize(statement_);
    statement_ = std::exchange(other.statement_, nullptr);
  }
  return *this;
}

std::string Statement::sql() const {
  const char* text = sqlite3_sql(statement_);
  return text == nullptr ? std::string() : std::string(text);
}

void Statement::check_bind(int code, int index) {
  if (code == SQLITE_OK) return;
  sqlite3* db = sqlite3_db_handle(statement_);
  fail(db, filename_of(db), code,
       "cannot bind parameter " + std::to_string(index) + " (of " +
           std::to_string(sqlite3_bind_parameter_count(statement_)) + ") of",
       sql());
}

Statement& Statement::bind_int64(int index, std::int64_t value) {
  check_bind(sqlite3_bind_int64(statement_, index, value), index);
  return *this;
}

Statement& Statement::bind_double(int index, double value) {
  check_bind(sqlite3_bind_double(statement_, index, value), index);
  return *this;
}

Statement& Statement::bind_text(int index, std::string_view utf8) {
  // A null pointer would bind NULL, not the empty string.
  const char* data = utf8.empty() ? "" : utf8.data();
  check_bind(sqlite3_bind_text64(statement_, index, data, utf8.size(), kTransient, SQLITE_UTF8),
             index);
  return *this;
}

Statement& Statement::bind_blob(int index, std::string_view bytes) {
  if (bytes.empty()) {
    // A null pointer would bind NULL, not the empty blob.
    check_bind(sqlite3_bind_zeroblob(statement_, index, 0), index);
  } else {
    check_bind(sqlite3_bind_blob64(statement_, index, bytes.data(), bytes.size(), kTransient),
               index);
  }
  return *this;
}

Statement& Statement::bind_null(int index) {
  check_bind(sqlite3_bind_null(statement_, index), index);
  return *this;
}

bool Statement::step() {
  const int code = sqlite3_step(statement_);
  if (code == SQLITE_ROW) return true;
  if (code == SQLITE_DONE) return false;
  sqlite3* db = sqlite3_db_handle(statement_);
  SqliteError error = make_error(db, filename_of(db), code, "cannot run", sql());
  // Ready to run again once the caller has dealt with the error.
  sqlite3_reset(statement_);
  throw error;
}

int Statement::column_count() const { return sqlite3_column_count(statement_); }

void Statement::check_column(int column) const {
  if (column < 0 || column >= column_count()) {
    throw InvalidInputError("column " + std::to_string(column) + " out of range: SQL '" +
                            excerpt(sql()) + "' has " + std::to_string(column_count()) +
                            " result columns (0-based index)");
  }
}

bool Statement::column_is_null(int column) const {
  check_column(column);
  return sqlite3_column_type(statement_, column) == SQLITE_NULL;
}

std::int64_t Statement::column_int64(int column) const {
  check_column(column);
  return sqlite3_column_int64(statement_, column);
}

double Statement::column_double(int column) const {
  check_column(column);
  return sqlite3_column_double(statement_, column);
}

std::string Statement::column_text(int column) const {
  check_column(column);
  // Pointer first, then the size (the order SQLite documents).
  const unsigned char* text = sqlite3_column_text(statement_, column);
  const int size = sqlite3_column_bytes(statement_, column);
  if (text == nullptr) return {};
  return {reinterpret_cast<const char*>(text),  // NOLINT(*-reinterpret-cast)
          static_cast<std::size_t>(size)};
}

std::string Statement::column_blob(int column) const {
  check_column(column);
  const void* blob = sqlite3_column_blob(statement_, column);
  const int size = sqlite3_column_bytes(statement_, column);
  if (blob == nullptr) return {};
  return {static_cast<const char*>(blob), static_cast<std::size_t>(size)};
}

void Statement::reset() { sqlite3_reset(statement_); }

void Statement::clear_bindings() { sqlite3_clear_bindings(statement_); }

// --- Transaction ------------------------------------------------------------

Transaction::Transaction(Database& database) : database_(&database) {
  database_->exec("BEGIN IMMEDIATE");
}

void Transaction::commit() {
  database_->exec("COMMIT");
  done_ = true;
}

Transaction::~Transaction() {
  // SQLite itself rolls back on some errors (disk full, I/O error); only roll
  // back a transaction that is still open. Errors cannot be reported from a
  // destructor, and a failed rollback leaves the last committed state anyway.
  if (!done_ && sqlite3_get_autocommit(database_->handle()) == 0) {
    sqlite3_exec(database_->handle(), "ROLLBACK", nullptr, nullptr, nullptr);
  }
}

}  // namespace mmm::workflow

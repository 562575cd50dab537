#pragma once
// Small RAII wrapper over the SQLite C API for the study database: one
// connection (Database), prepared statements (Statement) and write
// transactions (Transaction). Nothing but <sqlite3.h> underneath.
//
// Crash safety. Every connection runs with
//   journal_mode = WAL     commits append to <db>-wal; readers never block the
//                          writer; a crash (SIGKILL) mid-transaction leaves the
//                          last committed state, recovered on the next open;
//   synchronous  = FULL    the WAL is fsync'ed at every commit. With WAL,
//                          NORMAL would already survive any process crash
//                          (committed pages are in the OS cache) but could lose
//                          the last commits on power loss or kernel crash.
//                          FULL makes a returned commit() durable, which the
//                          study needs: operator input (manual tasks) recorded
//                          in the database cannot be recomputed, and a node's
//                          "done" row must not vanish after its artifacts (which
//                          the ArtifactStore fsyncs) were reported. The price,
//                          one fsync per commit, is small next to node run times;
//   foreign_keys = ON      references between tables are enforced;
//   busy_timeout           a connection waits this long for another one's write
//                          lock before failing with SQLITE_BUSY.
//
// Every error is a SqliteError (an IoError: path() is the database file) whose
// message has the SQL (truncated) and sqlite3_errmsg.
//
// Threads: a Database is one connection; give each thread its own (they may
// share the file). A Statement belongs to the connection that prepared it and
// must be destroyed before it (a Database may be moved meanwhile).

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/errors.h"

struct sqlite3;
struct sqlite3_stmt;

namespace mmm::workflow {

// A failed SQLite call. code() is the extended result code (SQLITE_BUSY,
// SQLITE_CONSTRAINT_UNIQUE, ... from <sqlite3.h>).
class SqliteError : public IoError {
 public:
  SqliteError(const std::filesystem::path& database, const std::string& problem, int code)
      : IoError(database, problem), code_(code) {}
  [[nodiscard]] int code() const { return code_; }

 private:
  int code_;
};

struct DatabaseOptions {
  // How long a statement waits for a lock held by another connection before
  // failing with SQLITE_BUSY (milliseconds).
  std::chrono::milliseconds busy_timeout{10000};
};

class Statement;

class Database {
 public:
  // Opens (creating if missing) the database file at `path` and applies the
  // settings above. Throws SqliteError naming the path when the file cannot be
  // opened or is not a database, or WAL mode cannot be enabled.
  explicit Database(std::filesystem::path path, const DatabaseOptions& options = {});
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;
  Database(Database&& other) noexcept;
  Database& operator=(Database&& other) noexcept;

  // Runs one or more ';'-separated statements without results (schema, pragmas).
  void exec(std::string_view sql);

  // Prepares one statement (see Statement).
  [[nodiscard]] Statement prepare(std::string_view sql);

  // Rowid of the last successful INSERT on this connection.
  [[nodiscard]] std::int64_t last_insert_rowid() const;

  // Rows changed by the last INSERT, UPDATE or DELETE on this connection.
  [[nodiscard]] int changes() const;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  // The raw handle, for calls this wrapper does not cover.
  [[nodiscard]] sqlite3* handle() const { return db_; }

 private:
  void close() noexcept;

  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
};

// A prepared statement. Parameters are bound by 1-based index (the `?` in
// order, or ?NNN); result columns are read by 0-based index, as in SQLite.
//   Statement insert = db.prepare("INSERT INTO node(name, runs) VALUES (?, ?)");
//   insert.bind_text(1, "fit").bind_int64(2, 3);
//   insert.step();
//   Statement select = db.prepare("SELECT name, runs FROM node");
//   while (select.step()) use(select.column_text(0), select.column_int64(1));
class Statement {
 public:
  // Prepares the first statement of `sql`; throws SqliteError (naming the SQL)
  // on a syntax error, an unknown table or column, or trailing extra statements.
  Statement(Database& database, std::string_view sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&& other) noexcept;

  // Binding (1-based index); each returns *this for chaining. Text and blobs
  // are copied, so the argument need not outlive the call.
  Statement& bind_int64(int index, std::int64_t value);
  Statement& bind_double(int index, double value);
  Statement& bind_text(int index, std::string_view utf8);
  Statement& bind_blob(int index, std::string_view bytes);
  Statement& bind_null(int index);

  // Runs the statement one step: true when a result row is available (read it
  // with the column getters), false when the statement has finished. Throws
  // SqliteError on failure (constraint violation, SQLITE_BUSY after the busy
  // timeout, ...).
  bool step();

  // Readers of the current row (0-based column index). Conversions follow
  // SQLite (NULL reads as 0, 0.0 or ""). column_text and column_blob copy.
  [[nodiscard]] int column_count() const;
  [[nodiscard]] bool column_is_null(int column) const;
  [[nodiscard]] std::int64_t column_int64(int column) const;
  [[nodiscard]] double column_double(int column) const;
  [[nodiscard]] std::string column_text(int column) const;
  [[nodiscard]] std::string column_blob(int column) const;

  // Rewinds the statement to run again; bindings are kept.
  void reset();
  // Sets every parameter back to NULL.
  void clear_bindings();

  // The SQL text the statement was prepared from.
  [[nodiscard]] std::string sql() const;

 private:
  void check_bind(int code, int index);
  void check_column(int column) const;

  sqlite3_stmt* statement_ = nullptr;
};

// A write transaction: BEGIN IMMEDIATE on construction (takes the write lock
// up front, waiting up to the busy timeout, so it cannot fail half way for lack
// of the lock), COMMIT in commit(), ROLLBACK on destruction when commit() was
// not called (an exception unwinding through it undoes everything).
class Transaction {
 public:
  explicit Transaction(Database& database);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  Transaction(Transaction&&) = delete;
  Transaction& operator=(Transaction&&) = delete;

  // Commits; throws SqliteError on failure (the destructor then rolls back).
  void commit();

 private:
  Database* database_;
  bool done_ = false;
};

}  // namespace mmm::workflow

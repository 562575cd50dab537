#include "workflow/store/sqlite.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <stdexcept>
#include <string>
#include <thread>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::workflow {
namespace {

namespace fs = std::filesystem;
using namespace std::string_literals;

std::int64_t count_rows(Database& db, const std::string& table) {
  Statement count = db.prepare("SELECT count(*) FROM " + table);
  EXPECT_TRUE(count.step());
  return count.column_int64(0);
}

TEST(SqliteTest, InsertAndSelectEveryType) {
  const test::ScratchDir dir("sqlite");
  Database db(dir / "study.db");
  db.exec("CREATE TABLE value(i INTEGER, d REAL, s TEXT, b BLOB, n)");
  const std::string blob = "\0\x01\xff binary\n"s;
  Statement insert = db.prepare("INSERT INTO value(i, d, s, b, n) VALUES (?, ?, ?, ?, ?)");
  insert.bind_int64(1, -(std::int64_t{1} << 62))
      .bind_double(2, 0.1)
      .bind_text(3, "femur \xc3\xa9")
      .bind_blob(4, blob)
      .bind_null(5);
  EXPECT_FALSE(insert.step());
  EXPECT_EQ(db.changes(), 1);
  EXPECT_EQ(db.last_insert_rowid(), 1);
  // Empty text and empty blob are values, not NULL.
  insert.reset();
  insert.bind_int64(1, 7).bind_double(2, -2.5).bind_text(3, "").bind_blob(4, "").bind_int64(5, 1);
  EXPECT_FALSE(insert.step());
  EXPECT_EQ(db.last_insert_rowid(), 2);

  Statement select = db.prepare("SELECT i, d, s, b, n FROM value ORDER BY rowid");
  EXPECT_EQ(select.column_count(), 5);
  ASSERT_TRUE(select.step());
  EXPECT_EQ(select.column_int64(0), -(std::int64_t{1} << 62));
  EXPECT_EQ(select.column_double(1), 0.1);  // stored as an IEEE double: exact round trip
  EXPECT_EQ(select.column_text(2), "femur \xc3\xa9");
  EXPECT_EQ(select.column_blob(3), blob);
  EXPECT_TRUE(select.column_is_null(4));
  EXPECT_FALSE(select.column_is_null(3));
  ASSERT_TRUE(select.step());
  EXPECT_EQ(select.column_int64(0), 7);
  EXPECT_EQ(select.column_double(1), -2.5);
  EXPECT_EQ(select.column_text(2), "");
  EXPECT_FALSE(select.column_is_null(2));
  EXPECT_EQ(select.column_blob(3), "");
  EXPECT_FALSE(select.column_is_null(3));
  EXPECT_EQ(select.column_int64(4), 1);
  EXPECT_FALSE(select.step());
  EXPECT_THROW((void)select.column_int64(5), InvalidInputError);
}

TEST(SqliteTest, ResetAndClearBindingsRerunAStatement) {
  const test::ScratchDir dir("sqlite");
  Database db(dir / "study.db");
  db.exec("CREATE TABLE node(name TEXT NOT NULL, runs INTEGER)");
  Statement insert = db.prepare("INSERT INTO node(name, runs) VALUES (?1, ?2)");
  for (int i = 0; i < 3; ++i) {
    insert.bind_text(1, "node" + std::to_string(i)).bind_int64(2, i);
    insert.step();
    insert.reset();
  }
  insert.clear_bindings();
  insert.bind_text(1, "no runs");
  insert.step();
  EXPECT_EQ(count_rows(db, "node"), 4);
  Statement select = db.prepare("SELECT runs FROM node WHERE name = ?");
  select.bind_text(1, "no runs");
  ASSERT_TRUE(select.step());
  EXPECT_TRUE(select.column_is_null(0));
  EXPECT_EQ(db.prepare("UPDATE node SET runs = runs + 1 WHERE runs IS NOT NULL").step(), false);
  EXPECT_EQ(db.changes(), 3);
}

TEST(SqliteTest, TransactionRollsBackOnException) {
  const test::ScratchDir dir("sqlite");
  Database db(dir / "study.db");
  db.exec("CREATE TABLE event(what TEXT)");
  try {
    Transaction transaction(db);
    db.prepare("INSERT INTO event VALUES ('started')").step();
    db.prepare("INSERT INTO event VALUES ('half done')").step();
    throw std::runtime_error("node crashed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(count_rows(db, "event"), 0);
  {
    Transaction transaction(db);
    db.prepare("INSERT INTO event VALUES ('done')").step();
    transaction.commit();
  }
  EXPECT_EQ(count_rows(db, "event"), 1);
  // After a failed statement the transaction is still rolled back whole.
  db.exec("CREATE TABLE unique_name(name TEXT UNIQUE)");
  try {
    Transaction transaction(db);
    db.prepare("INSERT INTO unique_name VALUES ('a')").step();
    db.prepare("INSERT INTO unique_name VALUES ('a')").step();
    transaction.commit();
    FAIL() << "expected a constraint violation";
  } catch (const SqliteError& error) {
    EXPECT_EQ(error.code(), SQLITE_CONSTRAINT_UNIQUE);
  }
  EXPECT_EQ(count_rows(db, "unique_name"), 0);
}

TEST(SqliteTest, SecondConnectionInAnotherThreadSeesCommittedRows) {
  const test::ScratchDir dir("sqlite");
  const fs::path path = dir / "study.db";
  Database writer(path);
  writer.exec("CREATE TABLE node(name TEXT)");
  {
    Transaction transaction(writer);
    writer.prepare("INSERT INTO node VALUES ('committed')").step();
    transaction.commit();
  }
  // An open write transaction: its row must stay invisible to the reader, and
  // (WAL) must not block it.
  Transaction pending(writer);
  writer.prepare("INSERT INTO node VALUES ('pending')").step();

  std::int64_t seen = -1;
  std::string name;
  std::thread reader([&path, &seen, &name] {
    Database db(path);
    Statement select = db.prepare("SELECT count(*), max(name) FROM node");
    if (select.step()) {
      seen = select.column_int64(0);
      name = select.column_text(1);
    }
  });
  reader.join();
  EXPECT_EQ(seen, 1);
  EXPECT_EQ(name, "committed");
}

TEST(SqliteTest, ConnectionSettingsAreApplied) {
  const test::ScratchDir dir("sqlite");
  Database db(dir / "study.db");
  Statement journal = db.prepare("PRAGMA journal_mode");
  ASSERT_TRUE(journal.step());
  EXPECT_EQ(journal.column_text(0), "wal");
  Statement synchronous = db.prepare("PRAGMA synchronous");
  ASSERT_TRUE(synchronous.step());
  EXPECT_EQ(synchronous.column_int64(0), 2);  // 2 = FULL
  Statement foreign_keys = db.prepare("PRAGMA foreign_keys");
  ASSERT_TRUE(foreign_keys.step());
  EXPECT_EQ(foreign_keys.column_int64(0), 1);
  db.exec("CREATE TABLE study(id INTEGER PRIMARY KEY)");
  EXPECT_TRUE(fs::exists(dir / "study.db-wal"));
}

TEST(SqliteTest, ForeignKeysAreEnforced) {
  const test::ScratchDir dir("sqlite");
  Database db(dir / "study.db");
  db.exec(
      "CREATE TABLE node(id INTEGER PRIMARY KEY);"
      "CREATE TABLE run(node_id INTEGER NOT NULL REFERENCES node(id))");
  try {
    db.prepare("INSERT INTO run(node_id) VALUES (42)").step();
    FAIL() << "expected a foreign key violation";
  } catch (const SqliteError& error) {
    EXPECT_EQ(error.code(), SQLITE_CONSTRAINT_FOREIGNKEY);
    EXPECT_NE(std::string(error.what()).find("INSERT INTO run"), std::string::npos);
  }
}

TEST(SqliteTest, DirectoryPathGivesIoErrorWithPath) {
  const test::ScratchDir dir("sqlite");
  try {
    const Database db(dir.path());
    FAIL() << "expected IoError";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), dir.path());
    EXPECT_NE(std::string(error.what()).find(dir.path().string()), std::string::npos);
  }
}

TEST(SqliteTest, FileThatIsNotADatabaseGivesIoError) {
  const test::ScratchDir dir("sqlite");
  const auto path = test::write_file(dir / "study.db", std::string(4096, 'x'));
  EXPECT_THROW(Database{path}, IoError);
}

TEST(SqliteTest, SyntaxErrorNamesTheStatementAndTheDatabase) {
  const test::ScratchDir dir("sqlite");
  const fs::path path = dir / "study.db";
  Database db(path);
  for (const bool use_exec : {false, true}) {
    try {
      if (use_exec) {
        db.exec("CREATE TABLE ok(x); SELEC x FROM ok");
      } else {
        (void)db.prepare("SELEC x FROM ok");
      }
      FAIL() << "expected SqliteError";
    } catch (const SqliteError& error) {
      const std::string message = error.what();
      EXPECT_EQ(error.path(), path);
      EXPECT_NE(message.find(path.string()), std::string::npos) << message;
      EXPECT_NE(message.find("SELEC x FROM ok"), std::string::npos) << message;
      EXPECT_NE(message.find("syntax error"), std::string::npos) << message;
    }
  }
}

TEST(SqliteTest, LongSqlIsTruncatedInErrors) {
  const test::ScratchDir dir("sqlite");
  Database db(dir / "study.db");
  const std::string sql = "SELECT " + std::string(5000, '1') + " FROM missing_table";
  try {
    (void)db.prepare(sql);
    FAIL() << "expected SqliteError";
  } catch (const SqliteError& error) {
    const std::string message = error.what();
    EXPECT_LT(message.size(), 1000U) << message;
    EXPECT_NE(message.find("SELECT 111"), std::string::npos);
    EXPECT_NE(message.find("..."), std::string::npos);
    EXPECT_NE(message.find("missing_table"), std::string::npos);  // from sqlite3_errmsg
  }
}

TEST(SqliteTest, PrepareRefusesSeveralStatements) {
  const test::ScratchDir dir("sqlite");
  Database db(dir / "study.db");
  db.exec("CREATE TABLE t(x)");
  EXPECT_THROW((void)db.prepare("INSERT INTO t VALUES (1); INSERT INTO t VALUES (2)"), SqliteError);
  EXPECT_NO_THROW((void)db.prepare("INSERT INTO t VALUES (1);  \n"));
  EXPECT_EQ(count_rows(db, "t"), 0);
}

TEST(SqliteTest, BusyTimeoutEndsWithSqliteBusy) {
  const test::ScratchDir dir("sqlite");
  const fs::path path = dir / "study.db";
  Database first(path);
  first.exec("CREATE TABLE t(x)");
  Transaction holding(first);
  DatabaseOptions impatient;
  impatient.busy_timeout = std::chrono::milliseconds(20);
  Database second(path, impatient);
  try {
    const Transaction blocked(second);
    FAIL() << "expected SQLITE_BUSY";
  } catch (const SqliteError& error) {
    EXPECT_EQ(error.code() & 0xff, SQLITE_BUSY);
    EXPECT_NE(std::string(error.what()).find("BEGIN IMMEDIATE"), std::string::npos);
  }
}

TEST(SqliteTest, DatabaseAndStatementAreMovable) {
  const test::ScratchDir dir("sqlite");
  Database db(dir / "study.db");
  db.exec("CREATE TABLE t(x)");
  Statement insert = db.prepare("INSERT INTO t VALUES (?)");
  Database moved(std::move(db));
  Statement insert2 = std::move(insert);
  insert2.bind_int64(1, 5).step();
  EXPECT_EQ(count_rows(moved, "t"), 1);
  EXPECT_EQ(moved.path(), dir / "study.db");
}

// A runner SIGKILLed in the middle of a transaction loses exactly that
// transaction; everything committed before survives.
TEST(SqliteTest, SigkillMidTransactionKeepsCommittedRows) {
  const test::ScratchDir dir("sqlite");
  const fs::path path = dir / "study.db";
  {
    Database db(path);
    db.exec("CREATE TABLE event(what TEXT)");
  }
  std::array<int, 2> ready{};
  ASSERT_EQ(::pipe(ready.data()), 0);
  const pid_t child = ::fork();
  if (child == 0) {
    try {
      Database db(path);
      {
        Transaction transaction(db);
        db.prepare("INSERT INTO event VALUES ('committed')").step();
        transaction.commit();
      }
      Transaction open(db);
      db.prepare("INSERT INTO event VALUES ('lost')").step();
      const char byte = 'r';
      if (::write(ready[1], &byte, 1) != 1) ::_exit(2);
      while (true) ::pause();
    } catch (...) {
      ::_exit(1);
    }
  }
  ASSERT_GT(child, 0);
  ::close(ready[1]);
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  ::close(ready[0]);
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status));

  Database db(path);
  Statement select = db.prepare("SELECT what FROM event");
  ASSERT_TRUE(select.step());
  EXPECT_EQ(select.column_text(0), "committed");
  EXPECT_FALSE(select.step());
  // The dead writer's lock is gone: a new write transaction starts at once.
  Transaction transaction(db);
  transaction.commit();
}

}  // namespace
}  // namespace mmm::workflow

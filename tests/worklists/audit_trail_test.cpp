#include "worklists/audit_trail.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <regex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/hash/sha256.h"
#include "tests/support/test_data.h"
#include "worklists/audit_export.h"
#include "worklists/audit_verify.h"

namespace mmm::worklists {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::IsEmpty;
using ::testing::Pair;
using workflow::Statement;
using workflow::Transaction;

// A study-like folder with its database and an opened audit trail.
struct Trail {
  test::ScratchDir dir{"audit"};
  Database db{dir / "study.db"};

  Trail() { open_audit_trail(db, dir.path()); }

  AuditEntry append(const AuditEntry& entry, bool checkpoint = true) {
    Transaction transaction(db);
    AuditEntry appended = append_audit_entry(db, entry);
    transaction.commit();
    if (checkpoint) write_audit_checkpoint(dir.path(), db);
    return appended;
  }

  // n entries, checkpointed after each.
  void append_many(int n) {
    for (int i = 1; i <= n; ++i) append(entry(i));
  }

  // What an attacker with the sqlite3 shell does: the triggers go first.
  void tamper(const std::string& sql) {
    db.exec("DROP TRIGGER IF EXISTS audit_no_update; DROP TRIGGER IF EXISTS audit_no_delete");
    db.exec(sql);
  }

  // Rewrites row `row.seq` with `row` (hash recomputed when `rehash`).
  void rewrite(AuditRow row, bool rehash) {
    if (rehash) row.hash = audit_row_hash(row);
    db.exec("DROP TRIGGER IF EXISTS audit_no_update; DROP TRIGGER IF EXISTS audit_no_delete");
    db.prepare("DELETE FROM audit WHERE seq = ?").bind_int64(1, row.seq).step();
    insert_audit_row(db, row);
  }

  void set_meta_head(std::int64_t seq, const std::string& hash) {
    db.prepare("UPDATE meta SET value = ? WHERE key = 'audit_head'")
        .bind_text(1, nlohmann::json{{"seq", seq}, {"hash", hash}}.dump())
        .step();
  }

  static AuditEntry entry(int i) {
    AuditEntry e;
    const std::array<const char*, 6> actions = {"open",   "claim",   "submit",
                                                "reject", "correct", "accept"};
    e.action = actions.at(static_cast<std::size_t>(i % 6));
    e.operator_name = "operator " + std::to_string(i);
    e.task_id = "task-" + std::to_string(i);
    e.reason = e.action == "reject" ? "landmark 'LASIS' off the bone" : "";
    e.mmm_version = "0.1.0";
    e.before = {{"LASIS", {1.0, 2.0, 3.0 + i}}};
    e.after = {{"LASIS", {1.5, 2.0, 3.0 + i}}};
    e.images = nlohmann::json::array({std::string(64, 'a'), std::string(64, 'b')});
    return e;
  }

  AuditVerification verify() { return verify_audit(db, dir.path()); }
};

// (kind name, seq) of every problem, for exact comparisons.
std::vector<std::pair<std::string, std::int64_t>> found(const AuditVerification& verification) {
  std::vector<std::pair<std::string, std::int64_t>> out;
  for (const AuditProblem& problem : verification.problems) {
    out.emplace_back(audit_problem_kind_name(problem.kind), problem.seq);
  }
  return out;
}

TEST(AuditTrailTest, AppendedEntriesFormAnIntactChain) {
  Trail trail;
  EXPECT_TRUE(trail.verify().intact);  // empty, with its seq-0 checkpoint
  EXPECT_EQ(read_audit_checkpoint(trail.dir.path()), AuditHead{});
  trail.append_many(5);

  const std::vector<AuditEntry> entries = read_audit(trail.db);
  ASSERT_EQ(entries.size(), 5U);
  const std::regex utc_millis(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z)");
  std::string prev = kAuditGenesisHash;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const AuditEntry& e = entries[i];
    EXPECT_EQ(e.seq, static_cast<std::int64_t>(i) + 1);
    EXPECT_TRUE(std::regex_match(e.time, utc_millis)) << e.time;
    EXPECT_EQ(e.prev_hash, prev);
    EXPECT_TRUE(is_audit_hash(e.hash));
    EXPECT_EQ(e.after, Trail::entry(static_cast<int>(i) + 1).after);
    prev = e.hash;
  }
  const AuditHead head{5, entries.back().hash};
  EXPECT_EQ(read_audit_meta_head(trail.db), head);
  EXPECT_EQ(read_audit_checkpoint(trail.dir.path()), head);
  EXPECT_EQ(audit_database_head(trail.db), head);

  const AuditVerification verification = trail.verify();
  EXPECT_TRUE(verification.intact);
  EXPECT_THAT(verification.problems, IsEmpty());
  EXPECT_EQ(verification.entries, 5);
  EXPECT_EQ(verification.head_seq, 5);
  EXPECT_EQ(verification.head, entries.back().hash);
}

TEST(AuditTrailTest, CanonicalFormIsTheDocumentedOne) {
  AuditRow row;
  row.seq = 1;
  row.prev_hash = kAuditGenesisHash;
  row.time = "2026-01-02T03:04:05.006Z";
  row.operator_name = "ana";
  row.task_id = "t1";
  row.action = "claim";
  row.before_json = row.after_json = row.images_json = "null";
  EXPECT_EQ(audit_canonical_form(row),
            "mmm-audit-v1\nseq:1:1\nprev_hash:64:" + std::string(64, '0') +
                "\ntime:24:2026-01-02T03:04:05.006Z\noperator:3:ana\ntask_id:2:t1\naction:5:"
                "claim\nbefore:4:null\nafter:4:null\nreason:0:\nmmm_version:0:\nimages:4:null\n");
  // Computed outside mmm with Python's hashlib from the recipe in audit_canonical.h.
  EXPECT_EQ(audit_row_hash(row),
            "20eca223fbad9e038b6b7c4949ca6a4ae43742f01082dbfdaa0cc3e0cd71c0cb");
}

TEST(AuditTrailTest, HashCoversEveryField) {
  Trail trail;
  trail.append_many(1);
  const AuditRow row = read_audit_rows(trail.db).front();
  EXPECT_EQ(audit_row_hash(row), row.hash);
  std::vector<AuditRow> variants(11, row);
  variants[0].seq = 2;
  variants[1].prev_hash = std::string(64, '1');
  variants[2].time += " ";
  variants[3].operator_name += "x";
  variants[4].task_id += "x";
  variants[5].action = "accept";
  variants[6].before_json = "{}";
  variants[7].after_json = "{}";
  variants[8].reason = "x";
  variants[9].mmm_version += "x";
  variants[10].images_json = "[]";
  for (const AuditRow& variant : variants) EXPECT_NE(audit_row_hash(variant), row.hash);
  // Length prefixes: moving bytes from one field to the next changes the hash.
  AuditRow shifted = row;
  shifted.operator_name.pop_back();
  shifted.task_id.insert(0, 1, row.operator_name.back());
  EXPECT_NE(audit_row_hash(shifted), row.hash);
}

TEST(AuditTrailTest, AppendOutsideATransactionIsRefused) {
  Trail trail;
  EXPECT_THROW((void)append_audit_entry(trail.db, Trail::entry(1)), std::logic_error);
  EXPECT_THAT(read_audit(trail.db), IsEmpty());
}

TEST(AuditTrailTest, RolledBackEntryLeavesNoTrace) {
  Trail trail;
  trail.append_many(2);
  {
    Transaction transaction(trail.db);
    (void)append_audit_entry(trail.db, Trail::entry(3));
  }  // no commit
  EXPECT_EQ(read_audit(trail.db).size(), 2U);
  EXPECT_TRUE(trail.verify().problems.empty());
}

TEST(AuditTrailTest, CheckpointInsideATransactionIsRefused) {
  Trail trail;
  Transaction transaction(trail.db);
  (void)append_audit_entry(trail.db, Trail::entry(1));
  EXPECT_THROW(write_audit_checkpoint(trail.dir.path(), trail.db), std::logic_error);
}

TEST(AuditTrailTest, IllFormedEntriesAreRefusedNamingTheField) {
  Trail trail;
  const auto refused = [&trail](const AuditEntry& entry) -> std::string {
    Transaction transaction(trail.db);
    try {
      (void)append_audit_entry(trail.db, entry);
    } catch (const InvalidInputError& error) {
      return error.what();
    }
    return "accepted";
  };
  AuditEntry unknown = Trail::entry(1);
  unknown.action = "approve";
  EXPECT_THAT(refused(unknown), ::testing::HasSubstr("'action': unknown action 'approve'"));
  EXPECT_THAT(refused(unknown), ::testing::HasSubstr("hint: one of open, claim"));
  AuditEntry anonymous = Trail::entry(1);
  anonymous.operator_name.clear();
  EXPECT_THAT(refused(anonymous), ::testing::HasSubstr("'operator_name' is empty"));
  AuditEntry reject = Trail::entry(1);
  reject.action = "reject";
  reject.reason.clear();
  EXPECT_THAT(refused(reject), ::testing::HasSubstr("'reason' is empty for action 'reject'"));
  AuditEntry images = Trail::entry(1);
  images.images = 3;
  EXPECT_THAT(refused(images), ::testing::HasSubstr("'images': expected a JSON array"));
  AuditEntry latin1 = Trail::entry(1);
  latin1.reason = "caf\xe9";
  EXPECT_THAT(refused(latin1), ::testing::HasSubstr("'reason'"));
  EXPECT_THAT(read_audit(trail.db), IsEmpty());
}

TEST(AuditTrailTest, DatabaseRefusesUpdateAndDelete) {
  Trail trail;
  trail.append_many(2);
  EXPECT_THROW(trail.db.exec("UPDATE audit SET reason = 'x' WHERE seq = 1"), workflow::SqliteError);
  EXPECT_THROW(trail.db.exec("DELETE FROM audit WHERE seq = 2"), workflow::SqliteError);
  prepare_audit_tables(trail.db);  // idempotent
  EXPECT_TRUE(trail.verify().problems.empty());
}

// --- tampering, one kind per test ---------------------------------------------

TEST(AuditTamperTest, EditedFieldIsReportedAtItsSeq) {
  Trail trail;
  trail.append_many(5);
  trail.tamper("UPDATE audit SET after_json = '{\"LASIS\":[9,9,9]}' WHERE seq = 3");
  const AuditVerification verification = trail.verify();
  EXPECT_FALSE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("edited", 3)));
}

TEST(AuditTamperTest, EditedAndRehashedEntryIsGivenAwayByItsSuccessor) {
  Trail trail;
  trail.append_many(5);
  AuditRow row = read_audit_rows(trail.db)[2];
  row.reason = "nothing to see";
  trail.rewrite(row, /*rehash=*/true);
  const AuditVerification verification = trail.verify();
  EXPECT_FALSE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("edited", 3)));
}

TEST(AuditTamperTest, RehashedLastEntryIsGivenAwayByTheHeads) {
  Trail trail;
  trail.append_many(5);
  AuditRow row = read_audit_rows(trail.db)[4];
  row.operator_name = "someone else";
  trail.rewrite(row, /*rehash=*/true);
  EXPECT_THAT(found(trail.verify()),
              ElementsAre(Pair("checkpoint_mismatch", 5), Pair("meta_mismatch", 5)));
}

TEST(AuditTamperTest, ConsistentlyRewrittenChainIsCaughtOnlyByTheCheckpoint) {
  Trail trail;
  trail.append_many(5);
  std::vector<AuditRow> rows = read_audit_rows(trail.db);
  rows[1].after_json = "{}";
  for (std::size_t i = 1; i < rows.size(); ++i) {
    rows[i].prev_hash = rows[i - 1].hash;
    rows[i].hash = audit_row_hash(rows[i]);
    trail.rewrite(rows[i], /*rehash=*/false);
  }
  trail.set_meta_head(5, rows.back().hash);
  EXPECT_THAT(found(trail.verify()), ElementsAre(Pair("checkpoint_mismatch", 5)));
}

TEST(AuditTamperTest, DeletedMiddleEntryIsReportedAtItsSeq) {
  Trail trail;
  trail.append_many(5);
  trail.tamper("DELETE FROM audit WHERE seq = 3");
  const AuditVerification verification = trail.verify();
  EXPECT_FALSE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("deleted", 3)));
  EXPECT_EQ(verification.entries, 4);
}

TEST(AuditTamperTest, DeletedAndRenumberedEntriesShowTheGapAndTheMoves) {
  Trail trail;
  trail.append_many(5);
  trail.tamper("DELETE FROM audit WHERE seq = 3; UPDATE audit SET seq = seq - 1 WHERE seq > 3");
  EXPECT_THAT(found(trail.verify()), ElementsAre(Pair("deleted", 3), Pair("reordered", 3),
                                                 Pair("reordered", 4), Pair("meta_mismatch", 4)));
}

TEST(AuditTamperTest, SwappedEntriesAreReportedAsReordered) {
  Trail trail;
  trail.append_many(5);
  const std::string columns =
      "time, operator_name, task_id, action, before_json, after_json, reason, mmm_version, "
      "images_json, prev_hash, hash";
  trail.tamper("CREATE TEMP TABLE original AS SELECT * FROM audit; UPDATE audit SET (" + columns +
               ") = (SELECT " + columns +
               " FROM original WHERE original.seq = CASE audit.seq WHEN 2 THEN 4 ELSE 2 END) "
               "WHERE seq IN (2, 4)");
  const AuditVerification verification = trail.verify();
  EXPECT_FALSE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("reordered", 2), Pair("reordered", 4)));
  EXPECT_THAT(verification.problems[0].message, ::testing::HasSubstr("written as seq 4"));
}

TEST(AuditTamperTest, DeletedLastEntriesAreReportedAsTruncated) {
  Trail trail;
  trail.append_many(5);
  trail.tamper("DELETE FROM audit WHERE seq >= 4");
  EXPECT_THAT(found(trail.verify()), ElementsAre(Pair("meta_mismatch", 3), Pair("truncated", 4)));
  // Even with meta made to agree, the checkpoint outside the database remembers.
  trail.set_meta_head(3, audit_database_head(trail.db).hash);
  const AuditVerification verification = trail.verify();
  EXPECT_FALSE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("truncated", 4)));
  EXPECT_THAT(verification.problems[0].message, ::testing::HasSubstr("entries 4..5"));
  // The evidence is not overwritten by the next checkpoint write.
  EXPECT_THROW(write_audit_checkpoint(trail.dir.path(), trail.db), IoError);
  EXPECT_EQ(read_audit_checkpoint(trail.dir.path())->seq, 5);
}

TEST(AuditTamperTest, EntryAddedPastTheMetaHeadIsInserted) {
  Trail trail;
  trail.append_many(5);
  AuditRow forged = read_audit_rows(trail.db).back();
  forged.seq = 6;
  forged.prev_hash = forged.hash;
  forged.action = "accept";
  trail.rewrite(forged, /*rehash=*/true);
  const AuditVerification verification = trail.verify();
  EXPECT_FALSE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("inserted", 6)));
}

TEST(AuditTamperTest, DeletedCheckpointIsMissing) {
  Trail trail;
  trail.append_many(3);
  fs::remove(audit_checkpoint_path(trail.dir.path()));
  EXPECT_THAT(found(trail.verify()), ElementsAre(Pair("checkpoint_missing", 0)));
  EXPECT_FALSE(trail.verify().intact);
  EXPECT_THROW(write_audit_checkpoint(trail.dir.path(), trail.db), IoError);
  EXPECT_FALSE(fs::exists(audit_checkpoint_path(trail.dir.path())));
}

TEST(AuditTamperTest, CorruptCheckpointIsDamaged) {
  Trail trail;
  trail.append_many(3);
  const fs::path checkpoint = audit_checkpoint_path(trail.dir.path());
  test::write_file(checkpoint, R"({"format": "mmm-audit-checkpoint-v1", "seq": 3,)");
  const AuditVerification verification = trail.verify();
  EXPECT_FALSE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("checkpoint_damaged", 0)));
  EXPECT_THAT(verification.problems[0].message, ::testing::HasSubstr("audit.checkpoint"));
  EXPECT_THROW(write_audit_checkpoint(trail.dir.path(), trail.db), IoError);
  // A well-formed file with a hash that is not one is damaged too.
  test::write_file(checkpoint, R"({"format": "mmm-audit-checkpoint-v1", "seq": 3, "hash": "abc"})");
  EXPECT_THAT(found(trail.verify()), ElementsAre(Pair("checkpoint_damaged", 0)));
}

TEST(AuditTamperTest, EditedMetaHeadIsAMismatch) {
  Trail trail;
  trail.append_many(5);
  trail.set_meta_head(5, std::string(64, 'a'));
  EXPECT_THAT(found(trail.verify()), ElementsAre(Pair("meta_mismatch", 5)));
  trail.db.exec("UPDATE meta SET value = 'garbage' WHERE key = 'audit_head'");
  EXPECT_THAT(found(trail.verify()), ElementsAre(Pair("meta_mismatch", 5)));
  trail.db.exec("DELETE FROM meta WHERE key = 'audit_head'");
  const AuditVerification verification = trail.verify();
  EXPECT_FALSE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("meta_mismatch", 5)));
}

// --- the benign case ------------------------------------------------------------

TEST(AuditTrailTest, CrashBeforeCheckpointWriteIsOnlyAWarning) {
  Trail trail;
  trail.append_many(3);
  trail.append(Trail::entry(4), /*checkpoint=*/false);  // committed, then "crash"
  trail.append(Trail::entry(5), /*checkpoint=*/false);
  AuditVerification verification = trail.verify();
  EXPECT_TRUE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("checkpoint_behind", 4)));
  EXPECT_TRUE(is_audit_warning(verification.problems[0].kind));
  EXPECT_THAT(verification.problems[0].message, ::testing::HasSubstr("entries 4..5"));
  // The next write catches up.
  write_audit_checkpoint(trail.dir.path(), trail.db);
  verification = trail.verify();
  EXPECT_TRUE(verification.intact);
  EXPECT_THAT(verification.problems, IsEmpty());
}

TEST(AuditTrailTest, CrashAfterTheFirstEntryIsOnlyAWarning) {
  Trail trail;  // open_audit_trail wrote the empty trail's checkpoint
  trail.append(Trail::entry(1), /*checkpoint=*/false);
  const AuditVerification verification = trail.verify();
  EXPECT_TRUE(verification.intact);
  EXPECT_THAT(found(verification), ElementsAre(Pair("checkpoint_behind", 1)));
}

// --- export -----------------------------------------------------------------------

TEST(AuditExportTest, JsonHasEveryField) {
  Trail trail;
  trail.append_many(2);
  const std::vector<AuditEntry> entries = read_audit(trail.db);
  const nlohmann::json json = audit_to_json(entries);
  ASSERT_EQ(json.size(), 2U);
  const nlohmann::json& first = json[0];
  EXPECT_EQ(first["seq"], 1);
  EXPECT_EQ(first["operator"], "operator 1");
  EXPECT_EQ(first["task_id"], "task-1");
  EXPECT_EQ(first["action"], "claim");
  EXPECT_EQ(first["before"], Trail::entry(1).before);
  EXPECT_EQ(first["after"], Trail::entry(1).after);
  EXPECT_EQ(first["images"], Trail::entry(1).images);
  EXPECT_EQ(first["prev_hash"], kAuditGenesisHash);
  EXPECT_EQ(first["hash"], entries[0].hash);
  EXPECT_EQ(json[1]["prev_hash"], entries[0].hash);
  EXPECT_EQ(first.size(), 12U);
}

TEST(AuditExportTest, CsvQuotesCommasQuotesAndNewlines) {
  AuditEntry entry;
  entry.seq = 7;
  entry.time = "2026-01-02T03:04:05.006Z";
  entry.operator_name = "Doe, Jane";
  entry.task_id = "t7";
  entry.action = "reject";
  entry.reason = "the \"LASIS\" point\nis off\r\nby 5 mm";
  entry.mmm_version = "0.1.0";
  entry.before = nullptr;
  entry.after = {{"a", 1}, {"b", "x"}};
  entry.images = nlohmann::json::array({"h1"});
  entry.prev_hash = "p";
  entry.hash = "h";
  const std::string csv = audit_to_csv({entry});
  EXPECT_EQ(csv,
            "seq,time,operator,task_id,action,before,after,reason,mmm_version,images,prev_hash,"
            "hash\r\n"
            "7,2026-01-02T03:04:05.006Z,\"Doe, Jane\",t7,reject,null,"
            "\"{\"\"a\"\":1,\"\"b\"\":\"\"x\"\"}\","
            "\"the \"\"LASIS\"\" point\nis off\r\nby 5 mm\",0.1.0,\"[\"\"h1\"\"]\",p,h\r\n");
  EXPECT_EQ(audit_to_csv({}), csv.substr(0, csv.find("\r\n") + 2));
}

}  // namespace
}  // namespace mmm::worklists

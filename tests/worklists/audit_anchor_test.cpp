#include "worklists/audit_anchor.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "worklists/audit_canonical.h"
#include "worklists/audit_trail.h"

namespace mmm::worklists {
namespace {

using workflow::Database;
using workflow::Transaction;

// A study-like folder: database with its creation time and an audit trail.
struct AnchoredTrail {
  test::ScratchDir dir{"audit-anchor"};
  Database db{dir / "study.db"};

  AnchoredTrail() {
    open_audit_trail(db, dir.path());
    db.exec("INSERT INTO meta(key, value) VALUES ('created_at', '2026-11-27T10:00:00Z')");
  }

  void append(int i) {
    AuditEntry entry;
    entry.action = "submit";
    entry.operator_name = "ana";
    entry.task_id = "task-" + std::to_string(i);
    entry.mmm_version = "0.1.0";
    entry.after = {{"femoral_head_centre_r", {1.0, 2.0, 3.0 + i}}};
    Transaction transaction(db);
    (void)append_audit_entry(db, entry);
    transaction.commit();
    write_audit_checkpoint(dir.path(), db);
  }

  // What someone with write access to the whole folder can do: change an
  // entry and re-hash everything after it, meta head and checkpoint included.
  void rewrite_everything_from(std::size_t index) {
    db.exec("DROP TRIGGER IF EXISTS audit_no_update; DROP TRIGGER IF EXISTS audit_no_delete");
    std::vector<AuditRow> rows = read_audit_rows(db);
    rows[index].after_json = R"({"femoral_head_centre_r":[31.0,2.0,4.0]})";
    for (std::size_t i = index; i < rows.size(); ++i) {
      if (i > 0) rows[i].prev_hash = rows[i - 1].hash;
      rows[i].hash = audit_row_hash(rows[i]);
      db.prepare("DELETE FROM audit WHERE seq = ?").bind_int64(1, rows[i].seq).step();
      insert_audit_row(db, rows[i]);
    }
    const nlohmann::json head = {{"seq", rows.back().seq}, {"hash", rows.back().hash}};
    db.prepare("UPDATE meta SET value = ? WHERE key = 'audit_head'")
        .bind_text(1, head.dump())
        .step();
    nlohmann::json checkpoint =
        nlohmann::json::parse(test::read_text(audit_checkpoint_path(dir.path())));
    checkpoint["seq"] = rows.back().seq;
    checkpoint["hash"] = rows.back().hash;
    test::write_file(audit_checkpoint_path(dir.path()), checkpoint.dump());
  }
};

TEST(AuditAnchorTest, AChainRewrittenEndToEndPassesVerifyButNotItsAnchor) {
  AnchoredTrail trail;
  for (int i = 1; i <= 3; ++i) trail.append(i);
  const test::ScratchDir outside("audit-anchor-log");
  const AuditAnchor anchor = anchor_audit(trail.db, trail.dir.path(), outside / "anchors.jsonl");
  EXPECT_EQ(anchor.seq, 3);
  EXPECT_EQ(anchor.created_at, "2026-11-27T10:00:00Z");
  for (int i = 4; i <= 5; ++i) trail.append(i);
  (void)anchor_audit(trail.db, trail.dir.path(), outside / "anchors.jsonl");
  EXPECT_EQ(read_anchors(outside / "anchors.jsonl", "2026-11-27T10:00:00Z").size(), 2U);
  EXPECT_THAT(verify_anchors(trail.db, outside / "anchors.jsonl"), ::testing::IsEmpty());

  trail.rewrite_everything_from(1);
  EXPECT_TRUE(verify_audit(trail.db, trail.dir.path()).intact);  // consistent inside
  const std::vector<AuditProblem> problems = verify_anchors(trail.db, outside / "anchors.jsonl");
  ASSERT_EQ(problems.size(), 2U);
  EXPECT_EQ(problems[0].kind, AuditProblemKind::kAnchorMismatch);
  EXPECT_EQ(problems[0].seq, 3);
  EXPECT_THAT(problems[0].message, ::testing::HasSubstr("rewritten"));
  EXPECT_EQ(problems[1].seq, 5);
}

TEST(AuditAnchorTest, ALogWithoutThisStudyOrNotALogIsReported) {
  AnchoredTrail trail;
  trail.append(1);
  const test::ScratchDir outside("audit-anchor-log");
  test::write_file(
      outside / "other.jsonl",
      R"({"format":"mmm-audit-anchor","version":1,"study":"/x","created_at":"2020-01-01T00:00:00Z","seq":1,"hash":"00"})"
      "\n");
  const std::vector<AuditProblem> missing = verify_anchors(trail.db, outside / "other.jsonl");
  ASSERT_EQ(missing.size(), 1U);
  EXPECT_EQ(missing[0].kind, AuditProblemKind::kAnchorMissing);
  test::write_file(outside / "notes.txt", "hello\n");
  EXPECT_THAT([&] { (void)verify_anchors(trail.db, outside / "notes.txt"); },
              ::testing::ThrowsMessage<IoError>(::testing::HasSubstr("line 1 is not an mmm")));
}

}  // namespace
}  // namespace mmm::worklists

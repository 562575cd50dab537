#pragma once
// The audit trail of a study: every manual action on a worklist task (open,
// claim, release, submit, reject, accept, correct, cancel, reassign) as one
// append-only, hash-chained entry in the study database, table
//
//   audit(seq INTEGER PRIMARY KEY, time, operator_name, task_id, action,
//         before_json, after_json, reason, mmm_version, images_json,
//         prev_hash, hash)
//
// Chain. Entry n stores prev_hash = hash of entry n-1 (64 zeros for n = 1) and
// hash = SHA-256 of its canonical form, which covers seq, prev_hash and every
// field (audit_canonical.h spells it out so that an auditor can recompute it
// without mmm). Editing, deleting, reordering or inserting an entry therefore
// breaks the chain at that place; audit_verify.h tells which it was.
//
// Head. The chain head (seq and hash of the last entry) is kept in two more
// places, because whoever can edit the database can also rewrite the whole
// chain consistently (recompute every hash from the edited entry on), and that
// only shows against a copy of the head kept elsewhere:
//   meta 'audit_head'    {"seq": n, "hash": "..."} in the study database;
//   DIR/audit.checkpoint the same as a JSON file in the study folder.
//
// Order of writes. The caller's transaction holds its task change, the entry
// and the new meta 'audit_head' (append_audit_entry): they commit together or
// not at all, so meta always names the last entry unless someone edited the
// database. Only after the commit is the checkpoint file rewritten
// (write_audit_checkpoint, atomically: temporary file + rename). A crash
// between the two leaves the checkpoint *behind* the database by entries whose
// chain is intact — the one disagreement without tampering, which verify
// reports as a warning. The checkpoint can never be ahead of the database
// without entries having been removed, and meta can never disagree with the
// last entry. (Forged entries appended at the end with meta updated look the
// same as the crash: the warning names those entries for a human to look at;
// the next checkpoint write then covers them.)
//
// What this does not protect against: someone who rewrites the database and the
// checkpoint file together. The checkpoint is evidence against editing the
// database alone (with the sqlite3 shell, say); copying it to a place the
// operators cannot write is the next step if that is needed.
//
// The database also refuses UPDATE and DELETE on `audit` (triggers): that
// stops mistakes, not an attacker, who can drop the triggers.

#include <array>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/store/sqlite.h"
#include "worklists/audit_canonical.h"

namespace mmm::worklists {

using workflow::Database;

// The actions an entry may record.
// "override": the next entry's action was taken on the command line without
// the operator's token, by administrative override (the reason says why).
inline constexpr std::array<std::string_view, 10> kAuditActions = {
    "open",   "claim",   "release", "submit",   "reject",
    "accept", "correct", "cancel",  "reassign", "override"};

// NOLINTNEXTLINE(bugprone-exception-escape): nlohmann::json's noexcept move only asserts
struct AuditEntry {
  // Given by the caller.
  std::string action;         // one of kAuditActions
  std::string operator_name;  // who acted (non-empty)
  std::string task_id;        // the worklist task (non-empty)
  std::string reason;         // free text; required for "reject"
  std::string mmm_version;    // the program that recorded it (non-empty)
  nlohmann::json before;      // landmark values before the action (any JSON; null: none)
  nlohmann::json after;       // landmark values after the action
  nlohmann::json images;      // content hashes of the images shown: array, object or null

  // Filled by append_audit_entry (values given are ignored).
  std::int64_t seq = 0;   // 1, 2, 3, ... in the order of commit
  std::string time;       // UTC with milliseconds: "2026-11-22T14:03:00.123Z"
  std::string prev_hash;  // hash of entry seq - 1; 64 zeros for the first
  std::string hash;       // SHA-256 of the canonical form (audit_canonical.h)
};

// Seq and hash of the last entry; {0, kAuditGenesisHash} for an empty trail.
struct AuditHead {
  std::int64_t seq = 0;
  std::string hash = kAuditGenesisHash;

  bool operator==(const AuditHead&) const = default;
};

// Creates the audit table, its append-only triggers and (when missing) the
// meta table. Idempotent; runs inside or outside a transaction.
void prepare_audit_tables(Database& database);

// What opening a study does: prepare_audit_tables, then, when the trail is
// still empty and DIR/audit.checkpoint does not exist, writes the checkpoint
// of the empty trail (seq 0). From then on a missing checkpoint file is always
// a problem, even when a crash followed the very first entry. Call it outside
// a transaction.
void open_audit_trail(Database& database, const std::filesystem::path& study_dir);

// Appends `entry` and sets meta 'audit_head' to it; returns the entry with
// seq, time, prev_hash and hash filled. Must run inside the caller's open
// Transaction (so that the task change it records commits with it), which
// also makes the seq race-free; call write_audit_checkpoint after the commit.
// Throws std::logic_error when no transaction is open, InvalidInputError
// naming the field for an unknown action, an empty operator, task id or
// version, a "reject" without reason, images that are not an array, object or
// null, or text that is not UTF-8; SqliteError from the database.
AuditEntry append_audit_entry(Database& database, AuditEntry entry);

// DIR/audit.checkpoint.
std::filesystem::path audit_checkpoint_path(const std::filesystem::path& study_dir);

// Writes the database's chain head to DIR/audit.checkpoint atomically. Call it
// after the commit of the transaction that appended. It never moves the
// checkpoint backwards or onto another chain: when the existing checkpoint is
// ahead of the database, names an entry whose hash differs, is damaged, or is
// missing while the trail has more than one entry, it is left as it is (it
// is the evidence) and IoError naming the file is thrown with a hint to
// verify. Throws std::logic_error when a transaction is open on `database`.
void write_audit_checkpoint(const std::filesystem::path& study_dir, Database& database);

// Every entry in seq order. Throws IoError naming the database and the entry
// when a JSON column does not parse (the trail was edited: see verify_audit).
std::vector<AuditEntry> read_audit(Database& database);

// Every row as stored, in seq order (verify_audit reads these: they hash
// whatever the columns hold).
std::vector<AuditRow> read_audit_rows(Database& database);

// Writes `row` exactly as given (no hashing, no head update): the raw insert
// append_audit_entry uses, and what tests use to forge rows.
void insert_audit_row(Database& database, const AuditRow& row);

// Seq and hash of the last row.
AuditHead audit_database_head(Database& database);

// The operator of the latest entry with this action for this task, or
// std::nullopt when there is none (who submitted the values a reviewer
// looks at, whoever the task is assigned to now).
std::optional<std::string> last_operator_of(Database& database, const std::string& task_id,
                                            std::string_view action);

// meta 'audit_head'; std::nullopt when absent. Throws IoError naming the
// database when the value is not {"seq": n, "hash": "<64 hex>"}.
std::optional<AuditHead> read_audit_meta_head(Database& database);

// The checkpoint file's head; std::nullopt when the file does not exist.
// Throws IoError naming the file when it cannot be read or is not a
// checkpoint (not JSON, wrong format tag, seq or hash missing or ill-formed).
std::optional<AuditHead> read_audit_checkpoint(const std::filesystem::path& study_dir);

}  // namespace mmm::worklists

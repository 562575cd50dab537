#pragma once
// Verification of a study's audit trail (audit_trail.h): recomputes every
// entry's hash, follows the prev_hash links and compares the chain head with
// meta 'audit_head' and DIR/audit.checkpoint; names each problem, the entry
// it concerns and what it looks like.
//
// How the kinds are told apart. Each row first gets an *origin*: the seq its
// stored hash was computed for. Normally that is its own seq. Otherwise the
// neighbouring seqs are tried (64 either side, and one past the origin of the
// row its prev_hash names), since seq is part of the hash:
//   no origin found           kEdited: a field changed after it was hashed;
//   origin elsewhere           kReordered: the row holds the entry written as
//                              another seq (contents swapped, or renumbered);
//   seq <= 0, or a second row
//   with the same origin       kInserted (the genuine one of two is the one a
//                              later row's prev_hash names);
//   an origin 1..last that no
//   row has                    kDeleted, one problem per missing seq.
// Then the links: a row whose prev_hash is not the stored hash of the row
// before, where nothing above explains it, means that row before was edited
// and its hash recomputed ("rehashed"): kEdited at that seq. The last entry
// has no successor to give it away; the heads below do.
//
// Heads. meta 'audit_head' is written in the transaction of each entry, so it
// must name the last row (else kMetaMismatch); rows past a meta head that is
// otherwise right (and past the checkpoint) were inserted without mmm
// (kInserted). The checkpoint file is written after each commit, so:
//   missing (with entries)     kCheckpointMissing;
//   unreadable / not JSON      kCheckpointDamaged;
//   ahead of the last entry    kTruncated, seq = the first missing entry;
//   its entry's hash differs   kCheckpointMismatch: the chain up to there was
//                              rewritten consistently (the only trace of that);
//   behind, chain intact       kCheckpointBehind: a crash between commit and
//                              checkpoint write. A warning: intact stays true.
//
// Then the tasks table and the accepted results are checked against the
// chain (audit_cross_check.h): a chain that is intact but no longer describes
// the study's tasks and results is not "intact".

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/store/sqlite.h"

namespace mmm::worklists {

enum class AuditProblemKind {
  kEdited,              // seq: the entry whose content or hash was changed
  kDeleted,             // seq: the missing entry (one problem each)
  kReordered,           // seq: the position holding another entry's content
  kTruncated,           // seq: the first of the missing last entries
  kInserted,            // seq: the entry that mmm did not write
  kCheckpointMissing,   // seq: 0
  kCheckpointDamaged,   // seq: 0
  kCheckpointMismatch,  // seq: the checkpoint's seq
  kCheckpointBehind,    // seq: the first entry after the checkpoint (warning only)
  kMetaMismatch,        // seq: the last entry's seq (what meta should name)
  // Cross-checks of the tasks against the trail (audit_cross_check.h):
  kTaskUnaudited,    // seq: 0; a task no entry opened
  kValueMismatch,    // seq: the last accept/correct entry of the task (0: none)
  kArtifactChanged,  // seq: as kValueMismatch; a result artifact edited in place
  // Against an external anchor log (audit_anchor.h), when one is given:
  kAnchorMissing,   // seq: 0; the log holds no anchor of this study
  kAnchorMismatch,  // seq: the anchored entry, gone or with another hash
};

// "edited", "deleted", ..., "checkpoint_behind", "meta_mismatch".
std::string_view audit_problem_kind_name(AuditProblemKind kind);

// Whether the kind is a warning (a benign crash), not evidence of tampering.
bool is_audit_warning(AuditProblemKind kind);

struct AuditProblem {
  AuditProblemKind kind = AuditProblemKind::kEdited;
  std::int64_t seq = 0;
  std::string message;  // a sentence: what was found, where, what it means
};

struct AuditVerification {
  bool intact = true;                  // no problem but warnings
  std::vector<AuditProblem> problems;  // ordered by seq, then kind
  std::int64_t entries = 0;            // rows in the audit table
  std::int64_t head_seq = 0;           // the last row (0 when empty)
  std::string head;                    // its stored hash (64 zeros when empty)
};

// Checks the audit trail of the study in `study_dir` whose database is
// `database` (audit tables prepared). Reads only; never throws for what it
// finds (a damaged checkpoint or meta value is a problem, not an exception),
// only SqliteError when the database cannot be read.
AuditVerification verify_audit(workflow::Database& database,
                               const std::filesystem::path& study_dir);

}  // namespace mmm::worklists

#pragma once
// External anchors of a study's audit trail. Everything in a study folder can
// be rewritten by whoever can write the folder, the hash chain and its
// checkpoint included: a chain rewritten end to end and re-hashed is
// consistent. An anchor is the chain head (seq and hash) copied at a moment
// to a log outside the study (a file on another machine, a write-once share,
// a printed report): any later rewrite of the entries up to that seq changes
// their hashes, and `verify_anchors` finds it.
//
// The log is JSON lines, appended: {"format": "mmm-audit-anchor", "version":
// 1, "study": absolute folder, "created_at": the study's creation time (its
// identity), "seq", "hash", "anchored_at"}. An auditor keeps the log where
// the study's writers cannot change it.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "workflow/store/sqlite.h"
#include "worklists/audit_verify.h"

namespace mmm::worklists {

struct AuditAnchor {
  std::string study;       // the folder when anchored
  std::string created_at;  // the study's meta created_at: which study it is
  std::int64_t seq = 0;
  std::string hash;
  std::string anchored_at;  // UTC
};

// Appends the current chain head of the study to `log` (created when
// missing; one line, flushed to disk) and returns it. Throws IoError naming
// the log when it cannot be written.
AuditAnchor anchor_audit(workflow::Database& database, const std::filesystem::path& study_dir,
                         const std::filesystem::path& log);

// The anchors of the study created at `created_at` in `log`, oldest first.
// Throws IoError naming the log (and the line) when it cannot be read or a
// line is not an anchor.
std::vector<AuditAnchor> read_anchors(const std::filesystem::path& log,
                                      const std::string& created_at);

// Problems of the chain against the log: kAnchorMissing when the log holds no
// anchor of this study (seq 0), kAnchorMismatch for each anchor whose entry
// is gone or has another hash now (seq: the anchored one).
std::vector<AuditProblem> verify_anchors(workflow::Database& database,
                                         const std::filesystem::path& log);

}  // namespace mmm::worklists

#pragma once
// One audit entry as stored in the study database (table `audit`, see
// audit_trail.h), and the canonical byte form its hash is computed over.
//
// Canonical form, version 1. Every value is the exact text stored in the
// column, UTF-8, with its length in bytes (decimal) in front, so no value can
// be confused with the separators whatever it contains:
//
//   "mmm-audit-v1\n"
//   then, for each field in this order, name ":" length ":" value "\n":
//     seq          the entry's number as decimal ASCII, no zeros in front
//     prev_hash    hash of the entry before (64 zeros for the first entry)
//     time         UTC, "2026-11-22T14:03:00.123Z"
//     operator     column operator_name
//     task_id
//     action
//     before       column before_json (compact JSON text as stored)
//     after        column after_json
//     reason
//     mmm_version
//     images       column images_json
//
//   hash = lowercase hexadecimal SHA-256 of those bytes.
//
// For example the entry {seq 1, time "2026-01-02T03:04:05.006Z", operator
// "ana", action "claim", task_id "t1", every other text empty, JSON fields
// "null"} is hashed over
//   mmm-audit-v1\nseq:1:1\nprev_hash:64:000...000\ntime:24:2026-01-02T03:04:05.006Z\n
//   operator:3:ana\ntask_id:2:t1\naction:5:claim\nbefore:4:null\nafter:4:null\n
//   reason:0:\nmmm_version:0:\nimages:4:null\n
// (no line breaks but the "\n"s). An auditor recomputes it outside mmm with
// `sqlite3 study.db "SELECT * FROM audit ORDER BY seq"` and a few lines of any
// language with SHA-256 (Python: hashlib.sha256(b"mmm-audit-v1\n" + b"".join(
// name + b":" + str(len(v)).encode() + b":" + v + b"\n" for name, v in fields))).
//
// The JSON columns are hashed as text, never re-serialized: the hash does not
// depend on any JSON library's number or escape formatting.

#include <cstdint>
#include <string>

namespace mmm::worklists {

// prev_hash of the first entry.
inline constexpr const char* kAuditGenesisHash =
    "0000000000000000000000000000000000000000000000000000000000000000";

// One row of the audit table, every field as stored.
struct AuditRow {
  std::int64_t seq = 0;
  std::string time;
  std::string operator_name;
  std::string task_id;
  std::string action;
  std::string before_json;
  std::string after_json;
  std::string reason;
  std::string mmm_version;
  std::string images_json;
  std::string prev_hash;
  std::string hash;  // not part of the canonical form
};

// The canonical bytes described above.
std::string audit_canonical_form(const AuditRow& row);

// Lowercase hex SHA-256 of audit_canonical_form(row): what row.hash must be.
std::string audit_row_hash(const AuditRow& row);

// Whether `text` is 64 lowercase hexadecimal characters (the form of every hash).
bool is_audit_hash(const std::string& text);

}  // namespace mmm::worklists

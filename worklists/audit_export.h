#pragma once
// The audit trail (audit_trail.h) as JSON and as CSV, for auditors and
// spreadsheets. Both keep every field, hashes included, so that an export can
// be checked against audit_canonical.h without the database.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "worklists/audit_trail.h"

namespace mmm::worklists {

// A JSON array, one object per entry in the order given, with the keys
//   seq, time, operator, task_id, action, before, after, reason, mmm_version,
//   images, prev_hash, hash
// (before, after and images as JSON values, the rest as numbers and strings).
nlohmann::json audit_to_json(const std::vector<AuditEntry>& entries);

// CSV (RFC 4180): a header row with the keys above, then one row per entry;
// lines end in CRLF; a cell holding a comma, a double quote, CR or LF is put
// in double quotes with its quotes doubled. before, after and images are their
// compact JSON text. Text cells are written byte for byte; a JSON cell with
// text that is not UTF-8 (only an edited database has it) gets U+FFFD.
// Cells are not guarded against spreadsheet formula interpretation (a reason
// starting with '='): that would change the data.
std::string audit_to_csv(const std::vector<AuditEntry>& entries);

}  // namespace mmm::worklists

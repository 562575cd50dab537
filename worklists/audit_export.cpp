#include "worklists/audit_export.h"

#include <array>
#include <string_view>

namespace mmm::worklists {
namespace {

// Compact JSON text; invalid UTF-8 replaced rather than thrown on.
std::string compact(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void append_cell(std::string& out, std::string_view cell) {
  if (cell.find_first_of(",\"\r\n") == std::string_view::npos) {
    out += cell;
    return;
  }
  out += '"';
  for (const char c : cell) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
}

void append_row(std::string& out, const std::array<std::string, 12>& cells) {
  bool first = true;
  for (const std::string& cell : cells) {
    if (!first) out += ',';
    first = false;
    append_cell(out, cell);
  }
  out += "\r\n";
}

}  // namespace

nlohmann::json audit_to_json(const std::vector<AuditEntry>& entries) {
  nlohmann::json out = nlohmann::json::array();
  for (const AuditEntry& entry : entries) {
    out.push_back({{"seq", entry.seq},
                   {"time", entry.time},
                   {"operator", entry.operator_name},
                   {"task_id", entry.task_id},
                   {"action", entry.action},
                   {"before", entry.before},
                   {"after", entry.after},
                   {"reason", entry.reason},
                   {"mmm_version", entry.mmm_version},
                   {"images", entry.images},
                   {"prev_hash", entry.prev_hash},
                   {"hash", entry.hash}});
  }
  return out;
}

std::string audit_to_csv(const std::vector<AuditEntry>& entries) {
  std::string out;
  append_row(out, {"seq", "time", "operator", "task_id", "action", "before", "after", "reason",
                   "mmm_version", "images", "prev_hash", "hash"});
  for (const AuditEntry& entry : entries) {
    append_row(out, {std::to_string(entry.seq), entry.time, entry.operator_name, entry.task_id,
                     entry.action, compact(entry.before), compact(entry.after), entry.reason,
                     entry.mmm_version, compact(entry.images), entry.prev_hash, entry.hash});
  }
  return out;
}

}  // namespace mmm::worklists

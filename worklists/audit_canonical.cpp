#include "worklists/audit_canonical.h"

#include <algorithm>
#include <string_view>

#include "core/hash/sha256.h"

namespace mmm::worklists {
namespace {

void append_field(std::string& out, std::string_view name, std::string_view value) {
  out += name;
  out += ':';
  out += std::to_string(value.size());
  out += ':';
  out += value;
  out += '\n';
}

}  // namespace

std::string audit_canonical_form(const AuditRow& row) {
  std::string out = "mmm-audit-v1\n";
  append_field(out, "seq", std::to_string(row.seq));
  append_field(out, "prev_hash", row.prev_hash);
  append_field(out, "time", row.time);
  append_field(out, "operator", row.operator_name);
  append_field(out, "task_id", row.task_id);
  append_field(out, "action", row.action);
  append_field(out, "before", row.before_json);
  append_field(out, "after", row.after_json);
  append_field(out, "reason", row.reason);
  append_field(out, "mmm_version", row.mmm_version);
  append_field(out, "images", row.images_json);
  return out;
}

std::string audit_row_hash(const AuditRow& row) {
  return hash::sha256_hex(audit_canonical_form(row));
}

bool is_audit_hash(const std::string& text) {
  if (text.size() != 64) return false;
  return std::ranges::all_of(
      text, [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

}  // namespace mmm::worklists

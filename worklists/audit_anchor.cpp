#include "worklists/audit_anchor.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "workflow/host_and_time.h"
#include "worklists/audit_trail.h"

namespace mmm::worklists {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr const char* kAnchorFormat = "mmm-audit-anchor";
constexpr int kAnchorVersion = 1;
// An anchor line is ~300 bytes; a log of a million anchors is ~300 MB.
constexpr std::uintmax_t kMaxLogBytes = std::uintmax_t{1} << 30U;

std::string study_created_at(workflow::Database& database) {
  workflow::Statement read = database.prepare("SELECT value FROM meta WHERE key = 'created_at'");
  return read.step() ? read.column_text(0) : std::string();
}

}  // namespace

AuditAnchor anchor_audit(workflow::Database& database, const fs::path& study_dir,
                         const fs::path& log) {
  const AuditHead head = audit_database_head(database);
  AuditAnchor anchor{fs::absolute(study_dir).lexically_normal().string(),
                     study_created_at(database), head.seq, head.hash, workflow::utc_now()};
  const Json line = {
      {"format", kAnchorFormat},          {"version", kAnchorVersion}, {"study", anchor.study},
      {"created_at", anchor.created_at},  {"seq", anchor.seq},         {"hash", anchor.hash},
      {"anchored_at", anchor.anchored_at}};
  const std::string text = line.dump() + "\n";
  // O_APPEND: one write of one line, so concurrent anchors never interleave.
  const int fd = ::open(log.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw IoError(log,
                  std::string("cannot open the anchor log for appending: ") + std::strerror(errno));
  }
  const ssize_t written = ::write(fd, text.data(), text.size());
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (written != static_cast<ssize_t>(text.size()) || !synced) {
    throw IoError(log, "could not append the anchor completely (disk full?)");
  }
  return anchor;
}

std::vector<AuditAnchor> read_anchors(const fs::path& log, const std::string& created_at) {
  std::error_code error;
  const std::uintmax_t size = fs::file_size(log, error);
  if (error) throw IoError(log, "cannot read the anchor log: " + error.message());
  if (size > kMaxLogBytes) throw IoError(log, "is larger than 1 GiB: not an anchor log");
  std::ifstream in(log);
  std::vector<AuditAnchor> anchors;
  std::string text;
  int number = 0;
  while (std::getline(in, text)) {
    ++number;
    if (text.empty()) continue;
    const Json line = parse_json_or_discarded(text);
    const std::string where = "line " + std::to_string(number);
    if (!line.is_object() || line.value("format", "") != kAnchorFormat ||
        line.value("version", 0) != kAnchorVersion || !line.contains("seq") ||
        !line["seq"].is_number_integer() || !line.contains("hash") || !line["hash"].is_string() ||
        !line.contains("created_at") || !line["created_at"].is_string()) {
      throw IoError(log, where +
                             " is not an mmm audit anchor; hint: give the log that 'mmm audit "
                             "anchor' appends to");
    }
    if (line["created_at"].get<std::string>() != created_at) continue;
    anchors.push_back({line.value("study", ""), created_at, line["seq"].get<std::int64_t>(),
                       line["hash"].get<std::string>(), line.value("anchored_at", "")});
  }
  return anchors;
}

std::vector<AuditProblem> verify_anchors(workflow::Database& database, const fs::path& log) {
  const std::string created_at = study_created_at(database);
  const std::vector<AuditAnchor> anchors = read_anchors(log, created_at);
  std::vector<AuditProblem> problems;
  if (anchors.empty()) {
    problems.push_back({AuditProblemKind::kAnchorMissing, 0,
                        log.string() + " holds no anchor of this study (created " + created_at +
                            "): it was never anchored there, or its creation time was changed"});
    return problems;
  }
  std::map<std::int64_t, std::string> stored;
  for (const AuditRow& row : read_audit_rows(database)) stored[row.seq] = row.hash;
  for (const AuditAnchor& anchor : anchors) {
    if (anchor.seq == 0) continue;  // the empty trail: nothing to compare
    const auto found = stored.find(anchor.seq);
    if (found == stored.end()) {
      problems.push_back({AuditProblemKind::kAnchorMismatch, anchor.seq,
                          "entry " + std::to_string(anchor.seq) + ", anchored " +
                              anchor.anchored_at + " in " + log.string() +
                              ", is no longer in the trail: it was deleted"});
    } else if (found->second != anchor.hash) {
      problems.push_back({AuditProblemKind::kAnchorMismatch, anchor.seq,
                          "entry " + std::to_string(anchor.seq) + " has hash " +
                              found->second.substr(0, 16) + "... but was anchored " +
                              anchor.anchored_at + " with " + anchor.hash.substr(0, 16) +
                              "...: the trail up to it was rewritten"});
    }
  }
  return problems;
}

}  // namespace mmm::worklists

// `mmm gc ROOT`: references from the databases, inode link counts for the
// shared store, a grace period on inode change times (root_gc.h).

#include "worklists/root_gc.h"

#include <sys/stat.h>
#include <unistd.h>

#include <map>
#include <optional>
#include <set>
#include <system_error>

#include "core/errors.h"
#include "workflow/store/artifact_store.h"
#include "workflow/store/errno_text.h"
#include "workflow/store/shared_store.h"
#include "workflow/store/sqlite.h"
#include "workflow/store/study_lock.h"
#include "worklists/worklist.h"

namespace mmm::worklists {

namespace fs = std::filesystem;

namespace {

struct BlobFile {
  fs::path path;
  std::string hash;
  dev_t device = 0;
  ino_t inode = 0;
  nlink_t links = 0;
  std::uintmax_t bytes = 0;
  bool young = false;  // its inode changed within the grace period
};

bool is_hex(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); }

// Every run of exactly 64 lowercase hex digits in `text`.
void add_hashes(std::string_view text, std::set<std::string, std::less<>>& hashes) {
  std::size_t run = 0;
  for (std::size_t i = 0; i <= text.size(); ++i) {
    if (i < text.size() && is_hex(text[i])) {
      ++run;
      continue;
    }
    if (run == 64) hashes.emplace(text.substr(i - 64, 64));
    run = 0;
  }
}

// Every hash mentioned anywhere in the study's databases.
std::set<std::string, std::less<>> referenced_hashes(const fs::path& study) {
  std::set<std::string, std::less<>> hashes;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(study, error)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".db") continue;
    workflow::Database database(entry.path());
    std::vector<std::string> tables;
    workflow::Statement list =
        database.prepare("SELECT name FROM sqlite_master WHERE type = 'table'");
    while (list.step()) tables.push_back(list.column_text(0));
    for (const std::string& table : tables) {
      std::string quoted = "\"";
      for (const char c : table) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
      workflow::Statement rows = database.prepare("SELECT * FROM " + quoted + "\"");
      while (rows.step()) {
        for (int column = 0; column < rows.column_count(); ++column) {
          add_hashes(rows.column_text(column), hashes);
        }
      }
    }
  }
  if (error) throw IoError(study, "cannot list the study folder: " + error.message());
  return hashes;
}

// The blobs of a store folder (<2 hex>/<62 hex>), with their inodes.
std::vector<BlobFile> list_blobs(const fs::path& store, std::chrono::seconds grace) {
  std::vector<BlobFile> blobs;
  std::error_code error;
  if (!fs::is_directory(store, error)) return blobs;
  const auto now = std::chrono::system_clock::now();
  for (const auto& shard : fs::directory_iterator(store, error)) {
    const std::string prefix = shard.path().filename().string();
    if (prefix.size() != 2 || !shard.is_directory()) continue;
    for (const auto& entry : fs::directory_iterator(shard.path(), error)) {
      BlobFile blob;
      blob.path = entry.path();
      blob.hash = prefix + entry.path().filename().string();
      if (!workflow::ArtifactStore::is_valid_hash(blob.hash)) continue;
      struct stat info {};
      if (::lstat(blob.path.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) continue;
      blob.device = info.st_dev;
      blob.inode = info.st_ino;
      blob.links = info.st_nlink;
      blob.bytes = static_cast<std::uintmax_t>(info.st_size);
      const auto changed = std::chrono::system_clock::time_point(
          std::chrono::seconds(info.st_ctim.tv_sec) +
          std::chrono::duration_cast<std::chrono::system_clock::duration>(
              std::chrono::nanoseconds(info.st_ctim.tv_nsec)));
      blob.young = now - changed < grace;
      blobs.push_back(std::move(blob));
    }
  }
  if (error) throw IoError(store, "cannot list the artifact store: " + error.message());
  return blobs;
}

using InodeKey = std::pair<dev_t, ino_t>;

void remove_file(const fs::path& path) {
  if (::unlink(path.c_str()) != 0 && errno != ENOENT) {
    throw IoError(path, "cannot remove: " + workflow::detail::errno_text(errno));
  }
}

}  // namespace

GcReport collect_garbage(const fs::path& root, const GcOptions& options) {
  GcReport report;
  report.applied = options.apply;
  const fs::path shared = root / workflow::kSharedStoreFolder;
  // The shared store's state before any study blob goes: the link counts
  // and change times this pass judges by.
  const std::vector<BlobFile> shared_blobs = list_blobs(shared, options.grace);
  std::map<InodeKey, nlink_t> links_removed;
  std::set<InodeKey> kept_inodes;
  for (const fs::path& study : find_studies(root)) {
    ++report.studies;
    std::optional<workflow::StudyLock> lock = workflow::StudyLock::try_acquire(study);
    const std::vector<BlobFile> blobs = list_blobs(study / "artifacts", options.grace);
    if (!lock) {
      report.busy_studies.push_back(study.lexically_relative(root).generic_string());
      for (const BlobFile& blob : blobs) {
        if (kept_inodes.insert({blob.device, blob.inode}).second) report.kept_bytes += blob.bytes;
      }
      continue;
    }
    const std::set<std::string, std::less<>> referenced = referenced_hashes(study);
    for (const BlobFile& blob : blobs) {
      const InodeKey key{blob.device, blob.inode};
      if (blob.young || referenced.contains(blob.hash)) {
        if (kept_inodes.insert(key).second) report.kept_bytes += blob.bytes;
        continue;
      }
      report.study_blobs.push_back({blob.path, blob.bytes});
      ++links_removed[key];
      if (blob.links == 1) report.freed_bytes += blob.bytes;  // its only name
      if (options.apply) remove_file(blob.path);
    }
  }
  for (const BlobFile& blob : shared_blobs) {
    const InodeKey key{blob.device, blob.inode};
    const auto removed = links_removed.find(key);
    const nlink_t remaining = blob.links - (removed == links_removed.end() ? 0 : removed->second);
    if (remaining > 1 || blob.young) {
      if (kept_inodes.insert(key).second) report.kept_bytes += blob.bytes;
      continue;
    }
    report.shared_blobs.push_back({blob.path, blob.bytes});
    report.freed_bytes += blob.bytes;
    if (options.apply) remove_file(blob.path);
  }
  if (options.apply && fs::is_directory(shared)) {
    (void)workflow::ArtifactStore(shared).remove_temporaries();
  }
  return report;
}

}  // namespace mmm::worklists

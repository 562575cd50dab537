#pragma once
// Garbage collection of the artifacts under a root folder (`mmm gc ROOT`):
// the blobs of each study that its databases no longer mention, and the
// blobs of the root's shared store (workflow/store/shared_store.h) that no
// study links any more.
//
// Never removes what a study still references:
// - a study's references are every SHA-256 (64 hex digits) in any text of
//   any table of its databases (inputs, executions and their history,
//   exports, tasks, audit): a superset of what it uses;
// - a study a runner holds (its lock) is left alone entirely, and so is
//   every blob whose inode changed (written, or linked by a study) within
//   the grace period: a blob written by `study set` or a task submission
//   before its record is committed is young;
// - a shared blob is removed only when the store's own name is its last
//   link (st_nlink 1, counting the study links this pass removes). A study
//   that links it at that moment gets ENOENT and writes its own copy
//   (ArtifactStore), so a concurrent run loses nothing.
// A dry run (the default) only reports.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace mmm::worklists {

struct GcOptions {
  bool apply = false;                   // remove (else only report)
  std::chrono::seconds grace{60 * 60};  // keep blobs whose inode changed since
};

struct GcBlob {
  std::filesystem::path path;
  std::uintmax_t bytes = 0;
};

struct GcReport {
  std::size_t studies = 0;
  std::vector<std::string> busy_studies;  // held by a runner: skipped
  std::vector<GcBlob> study_blobs;        // unreferenced blobs in studies
  std::vector<GcBlob> shared_blobs;       // shared blobs no study links
  // The bytes that go: shared files are counted once (a study blob that is
  // also in the store frees nothing until the store's name goes too).
  std::uintmax_t freed_bytes = 0;
  // What stays on disk under the root, each file (inode) counted once.
  std::uintmax_t kept_bytes = 0;
  bool applied = false;
};

// Throws IoError when `root` is not a folder or a study's database cannot
// be read (nothing is removed from that study then).
GcReport collect_garbage(const std::filesystem::path& root, const GcOptions& options);

}  // namespace mmm::worklists

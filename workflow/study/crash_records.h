#pragma once
// The crashes table (study_database.h): a node that crashed the process with
// given inputs and parameters (its cache key) is not run again with them
// unless asked to (`mmm run --retry-crashed`): one hostile input must not
// crash every later run of the study. The rows come from the crash marker the
// signal handler writes (workflow/run/crash_marker.h).

#include <optional>
#include <string>

#include "workflow/store/sqlite.h"

namespace mmm::workflow {

struct CrashRecord {
  std::string node;
  std::string cache_key;
  int signal = 0;
  std::string noticed_at;  // UTC: when the next run read the marker
};

// Records the crash, and turns the node's execution that was left 'running'
// with this key (when it was committed before the crash) into 'failed' with
// crash_error() as its error.
void record_crash(Database& database, const CrashRecord& crash);

// The latest crash of `node` with `cache_key`; std::nullopt when none.
std::optional<CrashRecord> find_crash(Database& database, const std::string& node,
                                      const std::string& cache_key);

// "SIGSEGV (invalid memory access or stack overflow)" and the like.
std::string signal_description(int signal);

// What a person reads about it: the signal, when, and what to do.
std::string crash_error(const CrashRecord& crash);

}  // namespace mmm::workflow

#pragma once
// What a node that crashes the process leaves behind. A node that throws is
// recorded as failed by the scheduler; a node that kills the process (a
// segmentation fault, an abort, a stack overflow on a hostile input) cannot
// record anything in the database. Instead, a signal handler appends one line
// to the study's crash marker file naming the node and its cache key; the
// next run turns the marker into a crash record (crash_records.h) and reports
// the node as failed instead of crashing again on the same input.
//
// The handler only uses async-signal-safe calls (open, write, fsync, close,
// sigaction, raise) and then hands the signal to whatever handled it before
// (the default action: a core dump; or a sanitizer's report). Worker threads
// get an alternate signal stack so that a stack overflow is recorded too.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::workflow {

struct MarkedCrash {
  int signal = 0;
  std::string node;
  std::string cache_key;
};

// Installs the crash handlers for SIGSEGV, SIGBUS, SIGFPE, SIGILL and SIGABRT
// while at least one object lives (counted: runs of several studies in one
// process share them); the handlers found before are restored after the last.
class CrashHandlers {
 public:
  CrashHandlers();
  ~CrashHandlers();
  CrashHandlers(const CrashHandlers&) = delete;
  CrashHandlers& operator=(const CrashHandlers&) = delete;
  CrashHandlers(CrashHandlers&&) = delete;
  CrashHandlers& operator=(CrashHandlers&&) = delete;
};

// While it lives, a crash on the calling thread appends
// "SIGNAL<TAB>NODE<TAB>CACHE_KEY" to `marker`.
class RunningNodeScope {
 public:
  RunningNodeScope(const std::filesystem::path& marker, std::string_view node,
                   std::string_view cache_key);
  ~RunningNodeScope();
  RunningNodeScope(const RunningNodeScope&) = delete;
  RunningNodeScope& operator=(const RunningNodeScope&) = delete;
  RunningNodeScope(RunningNodeScope&&) = delete;
  RunningNodeScope& operator=(RunningNodeScope&&) = delete;

 private:
  std::string path_;
  std::string line_;
};

// The crashes a marker file lists (none when it does not exist). Lines that
// do not parse are skipped; a file over 1 MiB is read up to that size.
std::vector<MarkedCrash> read_crash_marker(const std::filesystem::path& marker);

}  // namespace mmm::workflow

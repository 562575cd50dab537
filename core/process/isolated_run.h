#pragma once
// Runs a piece of work in a child process (fork), so that a library that
// aborts or crashes on hostile input takes down only the child. Debian's
// GDCM is built with assert() on, and its decoders (JPEG, JPEG-LS, JPEG 2000)
// are C code fed whatever bytes a file holds: a DICOM file is first decoded
// in a child, and the process that must survive (a study being created, a
// runner, the web station) decodes it only once the child came through.
//
// The child shares nothing back but whether it came through: the work's
// result, if any, stays in the child. The caller repeats the work (it is
// deterministic) to get it. A work that throws counts as coming through:
// the caller's own run throws the same error with its message.
//
// Caveats: fork() in a process with threads copies only the calling thread;
// a lock another thread held stays locked in the child. glibc's allocator is
// safe across fork; a child stuck on any other lock is killed at the time
// limit and reported as such, never left to hang the caller.

#include <chrono>
#include <functional>
#include <string>

namespace mmm::process {

struct IsolatedOutcome {
  bool came_through = false;  // the work returned or threw in the child
  bool timed_out = false;     // killed at the time limit
  int signal = 0;             // the signal that ended the child, 0 if none
  int exit_code = 0;          // the child's exit status when it exited otherwise
  // For messages: "aborted (SIGABRT)", "was killed after 60 s", ...
  [[nodiscard]] std::string description() const;
};

// Forks; the child resets the crash signals to their default action (so a
// fuzzer's or sanitizer's handler installed in the parent does not report
// the child's crash as its own), runs `work`, and ends with _exit (no
// destructors, no atexit handlers, no stdio buffers flushed twice). Throws
// std::system_error when fork or wait fails.
IsolatedOutcome run_isolated(const std::function<void()>& work, std::chrono::seconds time_limit);

}  // namespace mmm::process

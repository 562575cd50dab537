#pragma once
// Exclusive runner lock of a study folder: at most one process runs a study
// at a time.
//
// The lock is flock(2) LOCK_EX on `<study>/.lock`. The kernel releases it when
// the last descriptor of the open file description is closed, which includes
// the process dying for any reason: a SIGKILLed runner never leaves a stale
// lock, and no pid-file heuristics are needed. Each acquisition opens the file
// anew, so a second StudyLock on the same study conflicts even inside one
// process. After acquiring, the holder writes "pid <pid>\nhost <host>\nsince
// <UTC time>\n" into the file, only to tell a waiting runner who holds it.
// The file is never deleted (deleting a flock'ed file lets two runners lock two
// different files of the same name).
//
// The descriptor is opened O_CLOEXEC: a child started with exec does not
// inherit the lock. A child made by fork() alone shares it until it exits.

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "core/errors.h"

namespace mmm::workflow {

// Who holds a study lock, as written into the lock file by the holder.
struct StudyLockHolder {
  long pid = 0;
  std::string host;
  std::string since;  // UTC, ISO 8601 (e.g. 2024-05-01T12:00:00Z)
};

// The study is locked by another runner; what() names the study folder and the
// holder (pid, host) when it has recorded itself.
class StudyLockedError : public IoError {
 public:
  StudyLockedError(const std::filesystem::path& study, const std::string& problem,
                   std::optional<StudyLockHolder> holder)
      : IoError(study, problem), holder_(std::move(holder)) {}
  [[nodiscard]] const std::optional<StudyLockHolder>& holder() const { return holder_; }

 private:
  std::optional<StudyLockHolder> holder_;
};

class StudyLock {
 public:
  // Takes the lock if it is free; std::nullopt when another runner holds it.
  // Throws IoError when `study` is not an existing folder or the lock file
  // cannot be created.
  static std::optional<StudyLock> try_acquire(const std::filesystem::path& study);

  // Takes the lock, retrying every 50 ms for up to `timeout` (0: try once).
  // Throws StudyLockedError naming the study and the holder when still held.
  static StudyLock acquire(const std::filesystem::path& study, std::chrono::milliseconds timeout);

  // The holder recorded in `<study>/.lock`, if any (empty file, missing file:
  // std::nullopt). Does not tell whether the lock is currently held.
  static std::optional<StudyLockHolder> read_holder(const std::filesystem::path& study);

  // Releases the lock (clearing the holder record).
  ~StudyLock();
  StudyLock(const StudyLock&) = delete;
  StudyLock& operator=(const StudyLock&) = delete;
  StudyLock(StudyLock&& other) noexcept;
  StudyLock& operator=(StudyLock&& other) noexcept;

  [[nodiscard]] const std::filesystem::path& study() const { return study_; }

  // Releases the lock now; the object is then empty (destruction does nothing).
  void release() noexcept;

 private:
  StudyLock(std::filesystem::path study, int fd) : study_(std::move(study)), fd_(fd) {}

  std::filesystem::path study_;
  int fd_ = -1;
};

}  // namespace mmm::workflow

#include "workflow/store/study_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <sstream>
#include <system_error>
#include <thread>

#include "workflow/host_and_time.h"
#include "workflow/store/errno_text.h"

namespace mmm::workflow {
namespace {

constexpr const char* kLockFile = ".lock";
constexpr std::chrono::milliseconds kRetryInterval{50};

using detail::errno_text;

// Replaces the content of the locked file by the holder record. Informational
// only: a failure here does not affect the lock, so it is not an error.
void write_holder(int fd) {
  const std::string record =
      "pid " + std::to_string(::getpid()) + "\nhost " + host_name() + "\nsince " + utc_now() + "\n";
  if (::ftruncate(fd, 0) != 0) return;
  std::size_t written = 0;
  while (written < record.size()) {
    const ssize_t wrote =
        ::pwrite(fd, record.data() + written, record.size() - written, static_cast<off_t>(written));
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) return;
    written += static_cast<std::size_t>(wrote);
  }
}

std::string describe(const std::optional<StudyLockHolder>& holder) {
  if (!holder) return "another runner (which has not recorded its pid)";
  std::string text = "another runner (pid " + std::to_string(holder->pid);
  if (!holder->host.empty()) text += " on host " + holder->host;
  if (!holder->since.empty()) text += " since " + holder->since;
  return text + ")";
}

}  // namespace

std::optional<StudyLock> StudyLock::try_acquire(const std::filesystem::path& study) {
  std::error_code ignored;
  if (!std::filesystem::is_directory(study, ignored)) {
    throw IoError(study,
                  "cannot lock the study: the folder does not exist; create the study first");
  }
  const std::filesystem::path path = study / kLockFile;
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw IoError(path, "cannot open the study lock file: " + errno_text(errno) +
                            "; check that the study folder is writable");
  }
  while (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int code = errno;
    if (code == EINTR) continue;
    ::close(fd);
    if (code == EWOULDBLOCK) return std::nullopt;
    throw IoError(path, "cannot lock the study: " + errno_text(code));
  }
  write_holder(fd);
  return StudyLock(study, fd);
}

StudyLock StudyLock::acquire(const std::filesystem::path& study,
                             std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    std::optional<StudyLock> lock = try_acquire(study);
    if (lock) return std::move(*lock);
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) break;
    std::this_thread::sleep_for(
        std::min<std::chrono::steady_clock::duration>(kRetryInterval, deadline - now));
  }
  std::optional<StudyLockHolder> holder = read_holder(study);
  std::string problem = "the study is locked by " + describe(holder);
  if (timeout.count() > 0)
    problem += ", still after waiting " + std::to_string(timeout.count()) + " ms";
  problem +=
      "; wait for that run to finish or stop it (a stopped or killed runner releases the lock "
      "at once)";
  throw StudyLockedError(study, problem, std::move(holder));
}

std::optional<StudyLockHolder> StudyLock::read_holder(const std::filesystem::path& study) {
  const int fd = ::open((study / kLockFile).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::array<char, 1024> buffer{};
  const ssize_t got = ::pread(fd, buffer.data(), buffer.size(), 0);
  ::close(fd);
  if (got <= 0) return std::nullopt;
  std::istringstream in(std::string(buffer.data(), static_cast<std::size_t>(got)));
  StudyLockHolder holder;
  std::string line;
  while (std::getline(in, line)) {
    const auto space = line.find(' ');
    if (space == std::string::npos) continue;
    const std::string key = line.substr(0, space);
    const std::string value = line.substr(space + 1);
    if (key == "pid") {
      try {
        holder.pid = std::stol(value);
      } catch (const std::exception&) {
        return std::nullopt;
      }
    } else if (key == "host") {
      holder.host = value;
    } else if (key == "since") {
      holder.since = value;
    }
  }
  if (holder.pid <= 0) return std::nullopt;
  return holder;
}

StudyLock::~StudyLock() { release(); }

StudyLock::StudyLock(StudyLock&& other) noexcept
    : study_(std::move(other.study_)), fd_(std::exchange(other.fd_, -1)) {}

StudyLock& StudyLock::operator=(StudyLock&& other) noexcept {
  if (this != &other) {
    release();
    study_ = std::move(other.study_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

void StudyLock::release() noexcept {
  if (fd_ < 0) return;
  // Clear the record while still holding the lock, then let go.
  [[maybe_unused]] const int cleared = ::ftruncate(fd_, 0);
  ::close(fd_);
  fd_ = -1;
}

}  // namespace mmm::workflow

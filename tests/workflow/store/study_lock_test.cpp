#include "workflow/store/study_lock.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <string>
#include <thread>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::workflow {
namespace {

namespace fs = std::filesystem;

std::string this_host() {
  std::array<char, 256> name{};
  EXPECT_EQ(::gethostname(name.data(), name.size() - 1), 0);
  return name.data();
}

// A child process that takes the lock of `study`, reports 'y' (or 'n' when it
// could not) through a pipe, then holds it until killed or for `hold`.
struct LockingChild {
  pid_t pid = -1;
  char answer = 0;
};

LockingChild spawn_locking_child(const fs::path& study, std::chrono::milliseconds hold) {
  std::array<int, 2> pipe_fds{};
  EXPECT_EQ(::pipe(pipe_fds.data()), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipe_fds[0]);
    char answer = 'n';
    try {
      std::optional<StudyLock> lock = StudyLock::try_acquire(study);
      if (lock) answer = 'y';
      if (::write(pipe_fds[1], &answer, 1) != 1) ::_exit(2);
      if (hold.count() > 0) {
        std::this_thread::sleep_for(hold);
        ::_exit(0);
      }
      while (true) ::pause();
    } catch (...) {
      ::_exit(1);
    }
  }
  ::close(pipe_fds[1]);
  LockingChild child;
  child.pid = pid;
  EXPECT_EQ(::read(pipe_fds[0], &child.answer, 1), 1);
  ::close(pipe_fds[0]);
  return child;
}

int wait_for(pid_t pid) {
  int status = 0;
  EXPECT_EQ(::waitpid(pid, &status, 0), pid);
  return status;
}

TEST(StudyLockTest, SecondProcessFailsUntilTheHolderIsKilled) {
  const test::ScratchDir study("study-lock");
  const LockingChild holder = spawn_locking_child(study.path(), std::chrono::milliseconds(0));
  ASSERT_GT(holder.pid, 0);
  ASSERT_EQ(holder.answer, 'y');

  // Another process (this one) cannot take it.
  EXPECT_FALSE(StudyLock::try_acquire(study.path()).has_value());
  try {
    (void)StudyLock::acquire(study.path(), std::chrono::milliseconds(0));
    FAIL() << "expected StudyLockedError";
  } catch (const StudyLockedError& error) {
    const std::string message = error.what();
    EXPECT_EQ(error.path(), study.path());
    EXPECT_NE(message.find(study.path().string()), std::string::npos) << message;
    EXPECT_NE(message.find("pid " + std::to_string(holder.pid)), std::string::npos) << message;
    EXPECT_NE(message.find(this_host()), std::string::npos) << message;
    ASSERT_TRUE(error.holder().has_value());
    EXPECT_EQ(error.holder()->pid, holder.pid);
  }
  // A third process neither.
  const LockingChild third = spawn_locking_child(study.path(), std::chrono::milliseconds(1));
  EXPECT_EQ(third.answer, 'n');
  wait_for(third.pid);

  // SIGKILL leaves no stale lock: the kernel drops it with the process.
  ASSERT_EQ(::kill(holder.pid, SIGKILL), 0);
  const int status = wait_for(holder.pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  std::optional<StudyLock> lock = StudyLock::try_acquire(study.path());
  ASSERT_TRUE(lock.has_value());
  const auto recorded = StudyLock::read_holder(study.path());
  ASSERT_TRUE(recorded.has_value());
  EXPECT_EQ(recorded->pid, ::getpid());
  EXPECT_EQ(recorded->host, this_host());
  EXPECT_FALSE(recorded->since.empty());
}

TEST(StudyLockTest, SecondAcquireInTheSameProcessFails) {
  const test::ScratchDir study("study-lock");
  std::optional<StudyLock> first = StudyLock::try_acquire(study.path());
  ASSERT_TRUE(first.has_value());
  EXPECT_FALSE(StudyLock::try_acquire(study.path()).has_value());
  EXPECT_THROW((void)StudyLock::acquire(study.path(), std::chrono::milliseconds(0)),
               StudyLockedError);
  // Another thread is no different.
  bool other_thread_got_it = true;
  std::thread([&study, &other_thread_got_it] {
    other_thread_got_it = StudyLock::try_acquire(study.path()).has_value();
  }).join();
  EXPECT_FALSE(other_thread_got_it);
  first.reset();
  EXPECT_TRUE(StudyLock::try_acquire(study.path()).has_value());
}

TEST(StudyLockTest, ReleaseAndMoveHandOverTheLock) {
  const test::ScratchDir study("study-lock");
  StudyLock lock = StudyLock::acquire(study.path(), std::chrono::milliseconds(0));
  StudyLock moved = std::move(lock);
  EXPECT_EQ(moved.study(), study.path());
  EXPECT_FALSE(StudyLock::try_acquire(study.path()).has_value());
  moved.release();
  // The holder record is cleared on release.
  EXPECT_FALSE(StudyLock::read_holder(study.path()).has_value());
  EXPECT_TRUE(StudyLock::try_acquire(study.path()).has_value());
  // The lock file stays (deleting it would break mutual exclusion).
  EXPECT_TRUE(fs::exists(study / ".lock"));
}

TEST(StudyLockTest, AcquireWaitsForTheHolderToFinish) {
  const test::ScratchDir study("study-lock");
  // The child holds the lock for 300 ms, then exits; the 60 s timeout is only a
  // bound for a machine that is very slow, the wait normally ends at ~300 ms.
  const LockingChild holder = spawn_locking_child(study.path(), std::chrono::milliseconds(300));
  ASSERT_EQ(holder.answer, 'y');
  const StudyLock lock = StudyLock::acquire(study.path(), std::chrono::seconds(60));
  EXPECT_EQ(lock.study(), study.path());
  const int status = wait_for(holder.pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

TEST(StudyLockTest, MissingStudyFolderThrowsIoError) {
  const test::ScratchDir dir("study-lock");
  EXPECT_THROW((void)StudyLock::try_acquire(dir / "no_such_study"), IoError);
  EXPECT_FALSE(fs::exists(dir / "no_such_study"));
}

}  // namespace
}  // namespace mmm::workflow

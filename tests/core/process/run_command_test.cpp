// core/process/run_command.h: arguments go through uninterpreted, the exit
// status and output come back (bounded, keeping both ends), a missing program
// is a clear error, and a program given a parent-death signal ends with the
// thread that started it.

#include "core/process/run_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "core/errors.h"

namespace mmm::process {
namespace {

using ::testing::HasSubstr;

TEST(RunCommandTest, ArgumentsAreNotInterpretedAndTheStatusComesBack) {
  const CommandResult echoed = run_command({"printf", "%s|", "a b", "$HOME", "*"});
  EXPECT_EQ(echoed.exit_code, 0);
  EXPECT_EQ(echoed.output, "a b|$HOME|*|");
  EXPECT_EQ(run_command({"sh", "-c", "exit 7"}).exit_code, 7);
  EXPECT_EQ(run_command({"sh", "-c", "kill -TERM $$"}).exit_code, 128 + SIGTERM);
}

TEST(RunCommandTest, StandardInputIsEmpty) {
  EXPECT_EQ(run_command({"sh", "-c", "cat; echo end"}).output, "end\n");
}

TEST(RunCommandTest, LongOutputKeepsItsBeginningAndItsEnd) {
  const CommandResult result = run_command(
      {"sh", "-c", "echo first; yes middle | head -n 100000; echo last"}, {.max_output = 64});
  EXPECT_THAT(result.output, ::testing::StartsWith("first\n"));
  EXPECT_THAT(result.output, ::testing::EndsWith("last\n"));
  EXPECT_THAT(result.output, HasSubstr("[...]"));
  EXPECT_LT(result.output.size(), 64U + 16U);
}

TEST(RunCommandTest, AMissingProgramIsAnErrorWithAHint) {
  try {
    run_command({"mmm-no-such-program"});
    FAIL() << "expected an IoError";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("mmm-no-such-program"));
    EXPECT_THAT(error.what(), HasSubstr("hint"));
  }
}

// True while `pid` is a live process (not gone, not a zombie).
bool alive(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const std::size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

TEST(RunCommandTest, TheParentDeathSignalEndsTheProgramWhenItsStarterIsKilled) {
  // A child process starts `sleep` through run_command with SIGTERM as the
  // parent-death signal, then is killed (SIGKILL, as a coordinator can be):
  // the sleep ends at once instead of living on for 30 s.
  std::string pattern = "/tmp/mmm-run-command-XXXXXX";
  ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
  const std::string pid_file = pattern + "/pid";
  const pid_t starter = ::fork();
  ASSERT_GE(starter, 0);
  if (starter == 0) {
    run_command({"sh", "-c", "echo $$ > '" + pid_file + "'; exec sleep 30"},
                {.parent_death_signal = SIGTERM});
    ::_exit(0);
  }
  pid_t program = 0;
  for (int i = 0; i < 500 && program == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::ifstream(pid_file) >> program;
  }
  ASSERT_GT(program, 0);
  EXPECT_TRUE(alive(program));
  ::kill(starter, SIGKILL);
  ::waitpid(starter, nullptr, 0);
  bool ended = false;
  for (int i = 0; i < 500 && !ended; ++i) {
    ended = !alive(program);
    if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(ended) << "the program outlived its starter";
  if (!ended) ::kill(program, SIGKILL);
  std::filesystem::remove_all(pattern);
}

}  // namespace
}  // namespace mmm::process

#include "core/process/isolated_run.h"

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <system_error>
#include <thread>

namespace mmm::process {
namespace {

constexpr int kCameThrough = 0;
constexpr int kWorkFailedOddly = 70;  // an exception not derived from std::exception

std::string signal_name(int number) {
  switch (number) {
    case SIGABRT:
      return "SIGABRT: an assertion or abort()";
    case SIGSEGV:
      return "SIGSEGV: an invalid memory access";
    case SIGBUS:
      return "SIGBUS";
    case SIGFPE:
      return "SIGFPE: an arithmetic fault";
    case SIGILL:
      return "SIGILL";
    case SIGKILL:
      return "SIGKILL";
    default:
      return "signal " + std::to_string(number);
  }
}

[[noreturn]] void child(const std::function<void()>& work) {
  for (const int number : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL}) {
    struct sigaction action {};
    action.sa_handler = SIG_DFL;
    sigemptyset(&action.sa_mask);
    ::sigaction(number, &action, nullptr);
  }
  int status = kCameThrough;
  try {
    work();
  } catch (const std::exception&) {
    status = kCameThrough;  // the caller's own run throws it again
  } catch (...) {
    status = kWorkFailedOddly;
  }
  ::_exit(status);
}

}  // namespace

std::string IsolatedOutcome::description() const {
  if (came_through) return "came through";
  if (timed_out) return "did not finish within the time limit and was stopped";
  if (signal != 0) return "crashed (" + signal_name(signal) + ")";
  return "ended with exit status " + std::to_string(exit_code);
}

IsolatedOutcome run_isolated(const std::function<void()>& work, std::chrono::seconds time_limit) {
  const pid_t pid = ::fork();
  if (pid < 0) throw std::system_error(errno, std::generic_category(), "fork");
  if (pid == 0) child(work);

  IsolatedOutcome outcome;
  const auto deadline = std::chrono::steady_clock::now() + time_limit;
  auto pause = std::chrono::microseconds(200);
  int status = 0;
  while (true) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) {
      throw std::system_error(errno, std::generic_category(), "waitpid");
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      outcome.timed_out = true;
      return outcome;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20'000));
  }
  if (WIFSIGNALED(status)) {
    outcome.signal = WTERMSIG(status);
  } else if (WIFEXITED(status)) {
    outcome.exit_code = WEXITSTATUS(status);
    outcome.came_through = outcome.exit_code == kCameThrough;
  }
  return outcome;
}

}  // namespace mmm::process

#include "core/process/run_command.h"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

#include "core/errors.h"

namespace mmm::process {

CommandResult run_command(const std::vector<std::string>& argv, const CommandOptions& options) {
  if (argv.empty()) throw InvalidInputError("run_command: no program given");
  std::array<int, 2> output{};
  std::array<int, 2> exec_status{};  // closed on exec; carries errno when exec fails
  if (::pipe2(output.data(), O_CLOEXEC) != 0 || ::pipe2(exec_status.data(), O_CLOEXEC) != 0) {
    throw IoError(argv[0], std::string("cannot start: pipe: ") + std::strerror(errno));
  }
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw IoError(argv[0], std::string("cannot start: fork: ") + std::strerror(errno));
  if (pid == 0) {
    if (options.parent_death_signal != 0) {
      ::prctl(PR_SET_PDEATHSIG, options.parent_death_signal);
      if (::getppid() != parent) ::_exit(128 + options.parent_death_signal);  // already gone
    }
    const int nothing = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (nothing >= 0) ::dup2(nothing, STDIN_FILENO);
    ::dup2(output[1], STDOUT_FILENO);
    ::dup2(output[1], STDERR_FILENO);
    ::execvp(args[0], args.data());
    const int code = errno;
    (void)::write(exec_status[1], &code, sizeof(code));
    ::_exit(127);
  }
  ::close(output[1]);
  ::close(exec_status[1]);
  CommandResult result;
  const std::size_t head_limit = options.max_output - options.max_output / 2;
  const std::size_t tail_limit = options.max_output / 2;
  std::string tail;
  bool dropped = false;
  std::array<char, 4096> buffer{};
  while (true) {
    const ssize_t got = ::read(output[0], buffer.data(), buffer.size());
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    const auto count = static_cast<std::size_t>(got);
    const std::size_t to_head = std::min(count, head_limit - result.output.size());
    result.output.append(buffer.data(), to_head);
    if (to_head == count) continue;
    tail.append(buffer.data() + to_head, count - to_head);
    if (tail.size() > tail_limit) {
      tail.erase(0, tail.size() - tail_limit);
      dropped = true;
    }
  }
  if (dropped) result.output += "\n[...]\n";
  result.output += tail;
  ::close(output[0]);
  int exec_errno = 0;
  const ssize_t failed = ::read(exec_status[0], &exec_errno, sizeof(exec_errno));
  ::close(exec_status[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (failed == static_cast<ssize_t>(sizeof(exec_errno))) {
    throw IoError(argv[0], std::string("cannot be run: ") + std::strerror(exec_errno) +
                               "; hint: is it installed and on PATH?");
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

}  // namespace mmm::process

#include "workflow/run/crash_marker.h"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

namespace mmm::workflow {
namespace {

constexpr std::array<int, 5> kCrashSignals = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
constexpr std::size_t kMaxLine = 960;  // node ids and cache keys are far shorter
constexpr std::size_t kMaxMarkerBytes = std::size_t{1} << 20;
constexpr std::size_t kAltStackBytes = std::size_t{64} << 10;

// Handlers found before ours; written under g_install_mutex before ours are
// installed, read by the handler.
std::array<struct sigaction, kCrashSignals.size()> g_previous{};
std::mutex g_install_mutex;
int g_installed = 0;

// What the calling thread runs; read by the handler on the crashing thread.
constinit thread_local const char* t_marker_path = nullptr;
constinit thread_local const char* t_marker_line = nullptr;
constinit thread_local std::size_t t_marker_line_size = 0;

// An alternate signal stack for threads that have none, so that a stack
// overflow still reaches the handler. A thread that already has one (the
// sanitizers give every thread theirs) keeps it.
class AltStack {
 public:
  AltStack() = default;
  ~AltStack() {
    if (memory_.empty()) return;
    stack_t disable{};
    disable.ss_flags = SS_DISABLE;
    ::sigaltstack(&disable, nullptr);
  }
  AltStack(const AltStack&) = delete;
  AltStack& operator=(const AltStack&) = delete;
  AltStack(AltStack&&) = delete;
  AltStack& operator=(AltStack&&) = delete;

  void ensure() {
    if (!memory_.empty()) return;
    stack_t current{};
    if (::sigaltstack(nullptr, &current) != 0 || (current.ss_flags & SS_DISABLE) == 0) return;
    memory_.resize(kAltStackBytes);
    stack_t stack{};
    stack.ss_sp = memory_.data();
    stack.ss_size = memory_.size();
    if (::sigaltstack(&stack, nullptr) != 0) memory_ = {};
  }

 private:
  std::vector<char> memory_;
};

thread_local AltStack t_alt_stack;

std::size_t slot_of(int signal) {
  for (std::size_t slot = 0; slot < kCrashSignals.size(); ++slot) {
    if (kCrashSignals.at(slot) == signal) return slot;
  }
  return 0;
}

// Async-signal-safe: one write(2) of "SIGNAL\tLINE" on an O_APPEND file.
void append_marker(int signal) {
  std::array<char, kMaxLine + 16> buffer{};
  const std::to_chars_result number = std::to_chars(buffer.data(), buffer.data() + 12, signal);
  char* end = number.ptr;
  *end++ = '\t';
  std::memcpy(end, t_marker_line, t_marker_line_size);
  end += t_marker_line_size;
  const int fd = ::open(t_marker_path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return;
  [[maybe_unused]] const ssize_t wrote = ::write(fd, buffer.data(), end - buffer.data());
  ::fsync(fd);
  ::close(fd);
}

void on_crash(int signal, siginfo_t* info, void* /*context*/) {
  const int saved_errno = errno;
  // A fault of this process (si_code > 0: raised by the kernel) or raise()/
  // abort() in it; a signal sent by another process is not a node's crash.
  const bool raised_here = info == nullptr || info->si_code > 0 || info->si_pid == ::getpid();
  if (raised_here && t_marker_path != nullptr) {
    append_marker(signal);
    // Once per crash: the handler found before may end the process with a
    // second signal on this thread (a sanitizer's report then abort()).
    t_marker_path = nullptr;
  }
  // Hand over to the handler found before. A fault returns to the faulting
  // instruction, which faults again into it; a sent or raised signal is
  // raised again (blocked until this handler returns).
  ::sigaction(signal, &g_previous.at(slot_of(signal)), nullptr);
  if (info == nullptr || info->si_code <= 0) ::raise(signal);
  errno = saved_errno;
}

}  // namespace

CrashHandlers::CrashHandlers() {
  const std::lock_guard lock(g_install_mutex);
  if (g_installed++ > 0) return;
  struct sigaction action {};
  action.sa_sigaction = on_crash;
  action.sa_flags = SA_SIGINFO | SA_ONSTACK;
  sigemptyset(&action.sa_mask);
  for (std::size_t slot = 0; slot < kCrashSignals.size(); ++slot) {
    ::sigaction(kCrashSignals.at(slot), &action, &g_previous.at(slot));
  }
}

CrashHandlers::~CrashHandlers() {
  const std::lock_guard lock(g_install_mutex);
  if (--g_installed > 0) return;
  for (std::size_t slot = 0; slot < kCrashSignals.size(); ++slot) {
    ::sigaction(kCrashSignals.at(slot), &g_previous.at(slot), nullptr);
  }
}

RunningNodeScope::RunningNodeScope(const std::filesystem::path& marker, std::string_view node,
                                   std::string_view cache_key)
    : path_(marker.string()) {
  line_.append(node).append("\t").append(cache_key).append("\n");
  if (line_.size() > kMaxLine) line_.clear();  // not a node id: nothing sensible to record
  t_alt_stack.ensure();
  t_marker_line = line_.c_str();
  t_marker_line_size = line_.size();
  t_marker_path = line_.empty() ? nullptr : path_.c_str();
}

RunningNodeScope::~RunningNodeScope() {
  t_marker_path = nullptr;
  t_marker_line = nullptr;
  t_marker_line_size = 0;
}

std::vector<MarkedCrash> read_crash_marker(const std::filesystem::path& marker) {
  std::vector<MarkedCrash> crashes;
  std::ifstream in(marker, std::ios::binary);
  if (!in) return crashes;
  std::string text(kMaxMarkerBytes, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    const std::size_t first = line.find('\t');
    const std::size_t second = first == std::string::npos ? first : line.find('\t', first + 1);
    if (second == std::string::npos) continue;
    MarkedCrash crash;
    const std::from_chars_result number =
        std::from_chars(line.data(), line.data() + first, crash.signal);
    if (number.ec != std::errc() || number.ptr != line.data() + first) continue;
    crash.node = line.substr(first + 1, second - first - 1);
    crash.cache_key = line.substr(second + 1);
    if (crash.node.empty() || crash.cache_key.empty()) continue;
    crashes.push_back(std::move(crash));
  }
  return crashes;
}

}  // namespace mmm::workflow

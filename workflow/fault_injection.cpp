#include "workflow/fault_injection.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <string>

namespace mmm::workflow {
namespace {

struct FaultSettings {
  bool active = false;
  std::int64_t kill_at = 0;  // 0: never
  int trace_fd = -1;
};

FaultSettings read_settings() {
  FaultSettings settings;
  if (const char* kill_at = std::getenv("MMM_KILL_AT"); kill_at != nullptr && *kill_at != '\0') {
    settings.kill_at = std::strtoll(kill_at, nullptr, 10);
  }
  if (const char* trace = std::getenv("MMM_FAULT_TRACE"); trace != nullptr && *trace != '\0') {
    settings.trace_fd = ::open(trace, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  }
  settings.active = settings.kill_at > 0 || settings.trace_fd >= 0;
  return settings;
}

const FaultSettings& settings() {
  static const FaultSettings kSettings = read_settings();
  return kSettings;
}

std::atomic<std::int64_t> g_points_reached{0};
std::mutex g_trace_mutex;

}  // namespace

void fault_point(std::string_view name) {
  const FaultSettings& active = settings();
  if (!active.active) return;
  const std::int64_t count = g_points_reached.fetch_add(1) + 1;
  if (active.trace_fd >= 0) {
    const std::lock_guard lock(g_trace_mutex);
    const std::string line = std::string(name) + '\n';
    // One write(2) per line on an O_APPEND descriptor: lines never interleave.
    [[maybe_unused]] const ssize_t wrote = ::write(active.trace_fd, line.data(), line.size());
  }
  if (count == active.kill_at) ::kill(::getpid(), SIGKILL);
}

}  // namespace mmm::workflow

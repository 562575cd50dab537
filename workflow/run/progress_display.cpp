#include "workflow/run/progress_display.h"

#include <spdlog/spdlog.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <ostream>
#include <string>

#include "workflow/run/run_study.h"

namespace mmm::workflow {
namespace {

using Clock = std::chrono::steady_clock;

std::string seconds_text(double seconds) {
  std::array<char, 32> text{};
  std::snprintf(text.data(), text.size(), seconds < 10 ? "%.2f s" : "%.1f s", seconds);
  return text.data();
}

std::string progress_text(std::int64_t done, std::int64_t total, std::string_view what) {
  std::string text = std::string(what.empty() ? "" : std::string(what) + " ") +
                     std::to_string(done) + "/" + std::to_string(total);
  return text;
}

class TerminalDisplay final : public RunObserver {
 public:
  TerminalDisplay(std::ostream& out, const ProgressDisplayOptions& options)
      : out_(out), options_(options) {}

  void run_started(int nodes, int /*jobs*/) override {
    const std::lock_guard lock(mutex_);
    total_ = nodes;
  }
  void input_changed(std::string_view message) override {
    const std::lock_guard lock(mutex_);
    print_line(std::string(message));
  }
  void node_cached(const std::string& node) override {
    const std::lock_guard lock(mutex_);
    ++settled_;
    ++cached_;
    if (options_.show_cached) print_line("cached   " + node);
    redraw(true);
  }
  void node_started(const std::string& node, const std::string& type,
                    const std::string& reason) override {
    const std::lock_guard lock(mutex_);
    running_[node] = "";
    print_line("start    " + node + " (" + type + "): " + reason);
  }
  void node_progress(const std::string& node, std::int64_t done, std::int64_t total,
                     std::string_view what) override {
    const std::lock_guard lock(mutex_);
    running_[node] = progress_text(done, total, what);
    redraw(false);
  }
  void node_log(const std::string& node, LogLevel level, std::string_view message) override {
    if (level < LogLevel::kWarning) return;
    const std::lock_guard lock(mutex_);
    print_line((level == LogLevel::kError ? "error    " : "warning  ") + node + ": " +
               std::string(message));
  }
  void node_finished(const std::string& node, bool ok, double seconds,
                     const std::string& error) override {
    const std::lock_guard lock(mutex_);
    running_.erase(node);
    ++settled_;
    print_line(ok ? "done     " + node + " in " + seconds_text(seconds)
                  : "FAILED   " + node + ": " + error);
  }
  void node_waiting(const std::string& node) override {
    const std::lock_guard lock(mutex_);
    ++settled_;
    print_line("waiting  " + node + " (manual: waits for a person)");
  }
  void run_finished(const RunSummary& /*summary*/) override {
    const std::lock_guard lock(mutex_);
    clear_status();
    out_.flush();
  }

 private:
  void clear_status() {
    if (status_shown_) out_ << "\r\033[K";
    status_shown_ = false;
  }
  void print_line(const std::string& line) {
    clear_status();
    out_ << line << '\n';
    redraw(true);
  }
  void redraw(bool force) {
    const auto now = Clock::now();
    if (!force && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    std::string status = "[" + std::to_string(settled_) + "/" + std::to_string(total_) + "]";
    if (cached_ > 0) status += " " + std::to_string(cached_) + " cached";
    if (!running_.empty()) {
      status += " running:";
      bool first = true;
      for (const auto& [node, progress] : running_) {
        status += (first ? " " : ", ") + node + (progress.empty() ? "" : " (" + progress + ")");
        first = false;
      }
    }
    constexpr std::size_t kWidth = 110;
    if (status.size() > kWidth) status = status.substr(0, kWidth - 3) + "...";
    out_ << "\r\033[K" << status << std::flush;
    status_shown_ = true;
  }

  std::ostream& out_;
  ProgressDisplayOptions options_;
  std::mutex mutex_;
  int total_ = 0;
  int settled_ = 0;
  int cached_ = 0;
  std::map<std::string, std::string> running_;
  Clock::time_point last_draw_;
  bool status_shown_ = false;
};

class LogDisplay final : public RunObserver {
 public:
  explicit LogDisplay(const ProgressDisplayOptions& options) : options_(options) {}

  void run_started(int nodes, int jobs) override {
    spdlog::info("run: {} nodes, {} job(s)", nodes, jobs);
  }
  void input_changed(std::string_view message) override { spdlog::info("{}", message); }
  void node_cached(const std::string& node) override {
    if (options_.show_cached) spdlog::info("cached {}", node);
  }
  void node_started(const std::string& node, const std::string& type,
                    const std::string& reason) override {
    spdlog::info("start {} ({}): {}", node, type, reason);
  }
  void node_progress(const std::string& node, std::int64_t done, std::int64_t total,
                     std::string_view what) override {
    {
      const std::lock_guard lock(mutex_);
      const auto now = Clock::now();
      auto& last = last_progress_[node];
      if (done != total && now - last < std::chrono::seconds(5)) return;
      last = now;
    }
    spdlog::info("progress {}: {}", node, progress_text(done, total, what));
  }
  void node_log(const std::string& node, LogLevel level, std::string_view message) override {
    switch (level) {
      case LogLevel::kDebug:
        spdlog::debug("{}: {}", node, message);
        break;
      case LogLevel::kInfo:
        spdlog::info("{}: {}", node, message);
        break;
      case LogLevel::kWarning:
        spdlog::warn("{}: {}", node, message);
        break;
      case LogLevel::kError:
        spdlog::error("{}: {}", node, message);
        break;
    }
  }
  void node_finished(const std::string& node, bool ok, double seconds,
                     const std::string& error) override {
    if (ok) {
      spdlog::info("done {} in {}", node, seconds_text(seconds));
    } else {
      spdlog::error("FAILED {}: {}", node, error);
    }
  }
  void node_waiting(const std::string& node) override {
    spdlog::info("waiting {} (manual: waits for a person)", node);
  }

 private:
  ProgressDisplayOptions options_;
  std::mutex mutex_;
  std::map<std::string, Clock::time_point> last_progress_;
};

}  // namespace

std::unique_ptr<RunObserver> make_progress_display(std::ostream& out,
                                                   const ProgressDisplayOptions& options) {
  if (options.terminal) return std::make_unique<TerminalDisplay>(out, options);
  return std::make_unique<LogDisplay>(options);
}

}  // namespace mmm::workflow

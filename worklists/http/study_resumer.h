#pragma once
// Resuming studies in the background for `mmm serve`: once an operator's
// submission is accepted, the study's downstream nodes run on a thread of the
// server (run_study_with_tasks), so the workflow goes on without anybody
// typing `mmm run`.
//
//   request(study): the study is due now
//   dispatcher (one thread), woken by a request, a finished runner or a timer:
//     join the runner threads that finished
//     start a runner thread for every due study that has none
//       runner: open the study, run_study_with_tasks(wait 0)
//         locked by another process -> due again after retry_interval
//         requested again while running -> due again at once
//     every sweep_interval: studies with an accepted task and a node that
//       would run (plan_study: pending) are due (work accepted while no
//       server ran, or whose runner lost the lock race)
//
// One runner per study at a time: this process keeps at most one thread per
// study; other processes are kept out by the study's runner lock, and a
// locked study is simply retried.

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "workflow/node_registry.h"
#include "workflow/run/run_study.h"

namespace mmm::worklists::http {

struct ResumerOptions {
  // How the studies run (jobs, provenance); the observer is ignored.
  workflow::RunOptions run;
  // A study held by another runner is tried again after this long.
  std::chrono::milliseconds retry_interval{1000};
  // Period of the sweep over every study under the root; 0: no sweep.
  std::chrono::milliseconds sweep_interval{10000};
};

enum class RunnerState { kIdle, kQueued, kRunning };
std::string_view runner_state_name(RunnerState state);

struct RunnerStatus {
  RunnerState state = RunnerState::kIdle;
  std::string last_run;  // one sentence on the latest run of this server, empty: none
};

class StudyResumer {
 public:
  // `registry` must outlive the resumer; `log` receives one line per run
  // (called from runner threads, never concurrently).
  StudyResumer(std::filesystem::path root, const workflow::NodeRegistry& registry,
               ResumerOptions options, std::function<void(const std::string&)> log);
  // Waits for the running studies to finish their run.
  ~StudyResumer();
  StudyResumer(const StudyResumer&) = delete;
  StudyResumer& operator=(const StudyResumer&) = delete;
  StudyResumer(StudyResumer&&) = delete;
  StudyResumer& operator=(StudyResumer&&) = delete;

  // Runs the study in `study_dir` as soon as possible (at once when no runner
  // of this server has it; right after the current run otherwise).
  void request(const std::filesystem::path& study_dir);

  [[nodiscard]] RunnerStatus status(const std::filesystem::path& study_dir) const;

 private:
  struct Job {
    bool running = false;
    bool finished = false;  // the runner thread is done and waits to be joined
    bool again = false;     // requested while running
    std::optional<std::chrono::steady_clock::time_point> due;
    std::thread thread;
    std::string last_run;
  };

  void dispatch();
  void run_one(const std::filesystem::path& study_dir);
  // Studies with accepted work and a node that would run; a study that
  // cannot be read is skipped and named in `problems`.
  [[nodiscard]] std::vector<std::filesystem::path> sweep(std::vector<std::string>& problems) const;

  std::filesystem::path root_;
  const workflow::NodeRegistry& registry_;
  ResumerOptions options_;
  std::function<void(const std::string&)> log_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::map<std::filesystem::path, Job> jobs_;
  bool stopping_ = false;
  std::vector<std::string> last_sweep_problems_;  // logged once, not at every sweep
  std::mutex log_mutex_;
  std::thread dispatcher_;  // last: started once everything above exists
};

}  // namespace mmm::worklists::http

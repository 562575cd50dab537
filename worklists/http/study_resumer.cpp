#include "worklists/http/study_resumer.h"

#include <exception>
#include <set>
#include <utility>

#include "workflow/run/study_plan.h"
#include "workflow/study/study.h"
#include "worklists/study_runner.h"
#include "worklists/worklist.h"

namespace mmm::worklists::http {
namespace {

using Clock = std::chrono::steady_clock;

std::string join(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::string describe(const StudyRunResult& result) {
  if (result.locked) return "held by another runner (" + result.lock_holder + "); retrying";
  if (!result.summary) return "did not run";
  const workflow::RunSummary& summary = *result.summary;
  std::string text = std::string(workflow::run_outcome_name(summary.outcome)) + ": " +
                     std::to_string(summary.executed.size()) + " node(s) ran, " +
                     std::to_string(summary.cached.size()) + " cached";
  if (!summary.failed.empty()) text += ", failed: " + join(summary.failed);
  if (!summary.waiting.empty()) text += ", waiting: " + join(summary.waiting);
  if (!result.opened.empty()) {
    text += ", " + std::to_string(result.opened.size()) + " task(s) opened";
  }
  return text;
}

}  // namespace

std::string_view runner_state_name(RunnerState state) {
  switch (state) {
    case RunnerState::kIdle:
      return "idle";
    case RunnerState::kQueued:
      return "queued";
    case RunnerState::kRunning:
      return "running";
  }
  return "idle";
}

StudyResumer::StudyResumer(std::filesystem::path root, const workflow::NodeRegistry& registry,
                           ResumerOptions options, std::function<void(const std::string&)> log)
    : root_(std::move(root)),
      registry_(registry),
      options_(std::move(options)),
      log_(std::move(log)),
      dispatcher_([this] { dispatch(); }) {
  options_.run.observer = nullptr;
}

StudyResumer::~StudyResumer() {
  {
    const std::scoped_lock lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  dispatcher_.join();
}

void StudyResumer::request(const std::filesystem::path& study_dir) {
  {
    const std::scoped_lock lock(mutex_);
    Job& job = jobs_[study_dir];
    if (job.running) {
      job.again = true;
    } else {
      job.due = Clock::now();
    }
  }
  wake_.notify_all();
}

RunnerStatus StudyResumer::status(const std::filesystem::path& study_dir) const {
  const std::scoped_lock lock(mutex_);
  const auto found = jobs_.find(study_dir);
  if (found == jobs_.end()) return {};
  const Job& job = found->second;
  RunnerStatus status;
  status.last_run = job.last_run;
  if (job.running && !job.finished) {
    status.state = RunnerState::kRunning;
  } else if (job.due || job.again || job.finished) {
    status.state = RunnerState::kQueued;
  }
  return status;
}

void StudyResumer::dispatch() {
  std::unique_lock lock(mutex_);
  Clock::time_point next_sweep = Clock::now();
  while (!stopping_) {
    const Clock::time_point now = Clock::now();
    for (auto& [dir, job] : jobs_) {
      if (job.finished) {
        job.thread.join();
        job.finished = false;
        job.running = false;
        if (job.again) {
          job.again = false;
          job.due = now;
        }
      }
      if (!job.running && job.due && *job.due <= now) {
        job.due.reset();
        job.running = true;
        job.thread = std::thread([this, study_dir = dir] { run_one(study_dir); });
      }
    }
    if (options_.sweep_interval.count() > 0 && now >= next_sweep) {
      lock.unlock();
      std::vector<std::filesystem::path> found;
      std::vector<std::string> problems;
      try {
        found = sweep(problems);
      } catch (const std::exception& error) {
        problems.emplace_back(error.what());
      }
      if (!problems.empty() && problems != last_sweep_problems_) {
        const std::scoped_lock log_lock(log_mutex_);
        for (const std::string& problem : problems) log_("sweep: " + problem);
      }
      last_sweep_problems_ = problems;
      lock.lock();
      for (const std::filesystem::path& dir : found) {
        Job& job = jobs_[dir];
        if (!job.running && !job.due) job.due = Clock::now();
      }
      next_sweep = Clock::now() + options_.sweep_interval;
      continue;
    }
    Clock::time_point wake_at = Clock::now() + std::chrono::seconds(60);
    if (options_.sweep_interval.count() > 0) wake_at = std::min(wake_at, next_sweep);
    for (const auto& [dir, job] : jobs_) {
      if (job.finished) wake_at = now;
      if (!job.running && job.due) wake_at = std::min(wake_at, *job.due);
    }
    wake_.wait_until(lock, wake_at);
  }
  // Stopping: let the runs in progress finish (a run cannot be interrupted
  // halfway without leaving work to redo).
  std::vector<std::thread> running;
  for (auto& [dir, job] : jobs_) {
    if (job.thread.joinable()) running.push_back(std::move(job.thread));
  }
  lock.unlock();
  for (std::thread& thread : running) thread.join();
}

void StudyResumer::run_one(const std::filesystem::path& study_dir) {
  std::string message;
  bool locked = false;
  try {
    workflow::Study study = workflow::Study::open(study_dir, registry_);
    const StudyRunResult result =
        run_study_with_tasks(study, options_.run, std::chrono::milliseconds(0));
    locked = result.locked;
    message = describe(result);
  } catch (const std::exception& error) {
    message = std::string("failed: ") + error.what();
  }
  bool repeated = false;  // a study still locked is logged once, not at every retry
  {
    const std::scoped_lock lock(mutex_);
    Job& job = jobs_[study_dir];
    repeated = locked && job.last_run == message;
    job.finished = true;
    job.last_run = message;
    if (locked && !job.again) job.due = Clock::now() + options_.retry_interval;
  }
  wake_.notify_all();
  if (!repeated) {
    const std::scoped_lock log_lock(log_mutex_);
    log_("study " + study_dir.string() + ": " + message);
  }
}

std::vector<std::filesystem::path> StudyResumer::sweep(std::vector<std::string>& problems) const {
  WorklistFilter filter;
  filter.state = TaskState::kAccepted;
  filter.include_closed = true;
  std::set<std::filesystem::path> accepted;
  for (const WorklistEntry& entry : list_worklist(root_, filter)) accepted.insert(entry.study_dir);
  std::vector<std::filesystem::path> due;
  for (const std::filesystem::path& dir : accepted) {
    {
      const std::scoped_lock lock(mutex_);
      const auto found = jobs_.find(dir);
      if (found != jobs_.end() && (found->second.running || found->second.due)) continue;
    }
    try {
      workflow::Study study = workflow::Study::open(dir, registry_);
      const workflow::StudyPlan plan = workflow::plan_study(study, false);
      if (plan.count(workflow::NodeState::kPending) > 0) due.push_back(dir);
    } catch (const std::exception& error) {
      problems.push_back(dir.string() + ": " + error.what());
    }
  }
  return due;
}

}  // namespace mmm::worklists::http

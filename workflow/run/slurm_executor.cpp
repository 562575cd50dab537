#include "workflow/run/slurm_executor.h"

#include <sys/stat.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/process/run_command.h"
#include "workflow/host_and_time.h"
#include "workflow/run/node_request.h"

namespace mmm::workflow {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// Job states after which a job runs no more (squeue may still list it a moment).
const std::set<std::string, std::less<>>& final_states() {
  static const std::set<std::string, std::less<>> states = {
      "BOOT_FAIL", "CANCELLED", "COMPLETED",     "DEADLINE",     "FAILED",
      "NODE_FAIL", "PREEMPTED", "OUT_OF_MEMORY", "SPECIAL_EXIT", "TIMEOUT"};
  return states;
}

std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ' || text.back() == '\r')) {
    text.pop_back();
  }
  const std::size_t start = text.find_first_not_of(" \n");
  return start == std::string::npos ? std::string() : text.substr(start);
}

// 'text' quoted for sh: inside single quotes, a quote as '\''.
std::string shell_quoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

bool is_file(const fs::path& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode);
}

Completion failed(const Job& job, std::string error, Clock::time_point start) {
  Completion completion{job.node, job.execution_id, {}, std::move(error), {}, 0};
  completion.logs.push_back({utc_now_precise(), LogLevel::kError, completion.error});
  completion.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return completion;
}

}  // namespace

std::map<std::string, std::string> slurm_job_fields(const std::string& job_id) {
  std::map<std::string, std::string> fields;
  process::CommandResult shown;
  try {
    shown = process::run_command({"scontrol", "show", "job", "-o", job_id});
  } catch (const IoError&) {
    return fields;
  }
  if (shown.exit_code != 0) return fields;
  std::istringstream words(shown.output);
  std::string word;
  while (words >> word) {
    const std::size_t equals = word.find('=');
    if (equals != std::string::npos) fields[word.substr(0, equals)] = word.substr(equals + 1);
  }
  return fields;
}

Completion execute_on_slurm(const Job& job, const fs::path& artifacts,
                            const std::optional<fs::path>& pool, const fs::path& scratch_root,
                            const SlurmOptions& options, RunObserver* observer) {
  const auto start = Clock::now();
  const fs::path dir =
      fs::absolute(scratch_root / ("slurm-" + std::to_string(job.execution_id) + "-" + job.node));
  const fs::path request_file = dir / "request.json";
  const fs::path result_file = dir / "result.json";
  const fs::path log_file = dir / "slurm.log";
  std::string job_id;
  try {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
    fs::create_directories(dir);
    NodeRequest request{job, fs::absolute(artifacts), pool, dir / "work", result_file};
    write_file_atomically(request_file, node_request_text(request), "a node request");
    const fs::path script = dir / "job.sh";
    write_file_atomically(script,
                          "#!/bin/sh\nexec " + shell_quoted(options.executable.string()) +
                              " worker run-node " + shell_quoted(request_file.string()) + "\n",
                          "a job script");
    const NodeResources& resources = job.type->spec.resources();
    std::vector<std::string> sbatch = {"sbatch",
                                       "--parsable",
                                       "--job-name=mmm-" + job.node,
                                       "--output=" + log_file.string(),
                                       "--chdir=" + dir.string(),
                                       "--cpus-per-task=" + std::to_string(resources.threads),
                                       "--mem=" + std::to_string(resources.memory_mb) + "M"};
    sbatch.insert(sbatch.end(), options.sbatch_arguments.begin(), options.sbatch_arguments.end());
    sbatch.push_back(script.string());
    const process::CommandResult submitted = process::run_command(sbatch);
    job_id = trimmed(submitted.output.substr(0, submitted.output.find(';')));
    if (submitted.exit_code != 0 || job_id.empty() ||
        !std::all_of(job_id.begin(), job_id.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      return failed(job,
                    "sbatch refused node '" + job.node + "': " + trimmed(submitted.output) +
                        "; hint: check the cluster (sinfo) and SLURM_CONF",
                    start);
    }
  } catch (const std::exception& error) {
    return failed(
        job, std::string("cannot submit node '") + job.node + "' to Slurm: " + error.what(), start);
  }
  if (observer != nullptr) {
    observer->node_log(job.node, LogLevel::kInfo, "submitted as Slurm job " + job_id);
  }
  // Follow the job until squeue no longer lists it as queued or running.
  auto pause = std::chrono::milliseconds(20);
  while (true) {
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, options.poll);
    process::CommandResult queued;
    try {
      queued = process::run_command({"squeue", "-h", "-j", job_id, "-o", "%T"});
    } catch (const std::exception& error) {
      return failed(job, std::string("cannot follow Slurm job ") + job_id + ": " + error.what(),
                    start);
    }
    const std::string state = trimmed(queued.output);
    // Gone from the queue (or unknown to it), finished, or completing (the
    // script has ended; Slurm is cleaning up): nothing more will come.
    if (queued.exit_code != 0 || state.empty() || state == "COMPLETING" ||
        final_states().contains(state)) {
      break;
    }
    // The worker's result is written atomically, as its last act.
    if (is_file(result_file)) break;
  }
  if (is_file(result_file)) {
    try {
      const std::uintmax_t size = fs::file_size(result_file);
      Completion completion = completion_from_text(read_file_bytes(result_file, size), result_file);
      completion.logs.insert(completion.logs.begin(),
                             {utc_now_precise(), LogLevel::kInfo, "ran as Slurm job " + job_id});
      completion.seconds = std::chrono::duration<double>(Clock::now() - start).count();
      if (completion.error.empty()) {
        std::error_code ignored;
        fs::remove_all(dir, ignored);
      }
      return completion;
    } catch (const std::exception& error) {
      return failed(
          job, std::string("Slurm job ") + job_id + " left an unreadable result: " + error.what(),
          start);
    }
  }
  const std::map<std::string, std::string> fields = slurm_job_fields(job_id);
  const auto value = [&fields](const char* key) {
    const auto it = fields.find(key);
    return it == fields.end() ? std::string("unknown") : it->second;
  };
  return failed(job,
                "Slurm job " + job_id + " of node '" + job.node + "' ended " + value("JobState") +
                    " (reason " + value("Reason") + ", exit code " + value("ExitCode") +
                    ") without a result; its output: " + log_file.string() +
                    "; hint: the next run submits it again",
                start);
}

}  // namespace mmm::workflow

#include "workflow/run/slurm_executor.h"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <iomanip>
#include <sstream>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/process/run_command.h"
#include "workflow/host_and_time.h"
#include "workflow/run/node_request.h"

namespace mmm::workflow {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// srun's own messages kept for an error (its last lines say why it ended).
constexpr std::size_t kMaxSrunOutput = 8192;

std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ' || text.back() == '\r')) {
    text.pop_back();
  }
  const std::size_t start = text.find_first_not_of(" \n");
  return start == std::string::npos ? std::string() : text.substr(start);
}

// srun's messages on one line, for an error text.
std::string one_line(const std::string& text) {
  std::string line;
  for (const char c : trimmed(text)) line += c == '\n' ? std::string(" | ") : std::string(1, c);
  return line;
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

std::optional<SlurmJobState> find_slurm_job(const std::string& name, const std::string& comment) {
  process::CommandResult listed;
  try {
    listed = process::run_command(
        {"squeue", "--noheader", "--states=all", "--name=" + name, "--format=%i|%T|%r|%k"},
        {.max_output = std::size_t{1} << 20U});
  } catch (const IoError&) {
    return std::nullopt;
  }
  if (listed.exit_code != 0) return std::nullopt;
  std::istringstream lines(listed.output);
  std::string line;
  std::optional<SlurmJobState> found;
  while (std::getline(lines, line)) {
    std::array<std::string, 4> fields;
    std::istringstream cells(line);
    for (std::string& field : fields) std::getline(cells, field, '|');
    // The newest job of that name and comment: a re-run reuses the folder.
    if (fields[3] == comment) found = SlurmJobState{fields[0], fields[1], fields[2]};
  }
  return found;
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
  const std::string job_name = "mmm-" + job.node;
  process::CommandResult srun;
  try {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
    fs::create_directories(dir);
    NodeRequest request{job, fs::absolute(artifacts), pool, dir / "work", result_file};
    write_file_atomically(request_file, node_request_text(request), "a node request");
    const NodeResources& resources = job.type->spec.resources();
    // The comment (the job's folder) tells this job from any other of the
    // same name when Slurm is asked about it afterwards.
    std::vector<std::string> command = {"srun",
                                        "--job-name=" + job_name,
                                        "--comment=" + dir.string(),
                                        "--nodes=1",
                                        "--ntasks=1",
                                        "--cpus-per-task=" + std::to_string(resources.threads),
                                        "--mem=" + std::to_string(resources.memory_mb) + "M",
                                        "--input=none",
                                        "--output=" + log_file.string(),
                                        "--chdir=" + dir.string()};
    command.insert(command.end(), options.srun_arguments.begin(), options.srun_arguments.end());
    command.insert(command.end(),
                   {options.executable.string(), "worker", "run-node", request_file.string()});
    if (observer != nullptr) {
      observer->node_log(job.node, LogLevel::kInfo,
                         "submitted to Slurm (srun, job " + job_name + ")");
    }
    srun = process::run_command(command,
                                {.max_output = kMaxSrunOutput, .parent_death_signal = SIGTERM});
  } catch (const std::exception& error) {
    return failed(job,
                  std::string("cannot submit node '") + job.node + "' to Slurm: " + error.what() +
                      "; hint: is Slurm's srun installed here, and SLURM_CONF set?",
                  start);
  }
  const std::optional<SlurmJobState> slurm_job = find_slurm_job(job_name, dir.string());
  const std::string job_id = slurm_job ? slurm_job->id : std::string("(unknown id)");
  // The worker's result is written atomically, as its last act.
  if (is_file(result_file)) {
    try {
      const std::uintmax_t size = fs::file_size(result_file);
      Completion completion = completion_from_text(read_file_bytes(result_file, size), result_file);
      const double on_node = completion.seconds;
      completion.seconds = std::chrono::duration<double>(Clock::now() - start).count();
      // What Slurm added: waiting for the allocation, starting the worker,
      // ending the job (the node's own time is the worker's).
      std::ostringstream line;
      line << std::fixed << std::setprecision(3) << "ran as Slurm job " << job_id << ": " << on_node
           << " s on the node, " << std::max(0.0, completion.seconds - on_node)
           << " s more in Slurm (queued, started, ended)";
      completion.logs.insert(completion.logs.begin(),
                             {utc_now_precise(), LogLevel::kInfo, line.str()});
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
  std::string error = "Slurm job " + job_id + " of node '" + job.node + "' ended";
  if (slurm_job) error += " " + slurm_job->state + " (reason " + slurm_job->reason + ")";
  error += " without a result (srun exit code " + std::to_string(srun.exit_code) + ": " +
           one_line(srun.output) + "); the job's output: " + log_file.string() +
           "; hint: the next run submits it again";
  return failed(job, std::move(error), start);
}

}  // namespace mmm::workflow

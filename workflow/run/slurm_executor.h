#pragma once
// Node executions as Slurm jobs (`mmm run --executor slurm`, `mmm cohort run
// --executor slurm`). The runner stays the one process that writes the study
// database; for each node it writes a request (node_request.h) into the
// study's scratch folder, submits `mmm worker run-node REQUEST` with sbatch
// (the node type's threads and memory: NodeSpec::resources), follows the
// job with squeue, then reads the result the worker wrote. A job that ends
// without a result (cancelled with scancel, out of memory, out of time, a
// failed node host) becomes a failed execution whose error gives Slurm's job
// state and reason; the next run submits it again.
//
// Assumes a file system shared by the coordinator and the cluster's nodes,
// at the same paths (the study folder, the root's shared store and the mmm
// executable).

#include <chrono>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "workflow/run/node_execution.h"
#include "workflow/run/run_observer.h"

namespace mmm::workflow {

struct SlurmOptions {
  // The mmm executable the jobs run (the coordinator's own by default).
  std::filesystem::path executable;
  // Extra sbatch arguments, e.g. {"--partition=short", "--account=lab"}.
  std::vector<std::string> sbatch_arguments;
  // How often squeue is asked (the first few polls are quicker).
  std::chrono::milliseconds poll{100};
};

// Runs `job` as a Slurm job and waits for it; never throws (a failure to
// submit is the Completion's error). Its folder is
// `scratch_root`/slurm-<execution id>-<node>: request.json, job.sh,
// slurm.log (kept when the job failed), result.json.
Completion execute_on_slurm(const Job& job, const std::filesystem::path& artifacts,
                            const std::optional<std::filesystem::path>& pool,
                            const std::filesystem::path& scratch_root, const SlurmOptions& options,
                            RunObserver* observer);

// The fields of `scontrol show job -o ID` (JobState, Reason, ExitCode, ...),
// for messages; empty when Slurm no longer knows the job.
std::map<std::string, std::string> slurm_job_fields(const std::string& job_id);

}  // namespace mmm::workflow

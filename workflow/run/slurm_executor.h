#pragma once
// Node executions as Slurm jobs (`mmm run --executor slurm`, `mmm cohort run
// --executor slurm`). The runner stays the one process that writes the study
// database; for each node it writes a request (node_request.h) into the
// study's scratch folder and runs `srun ... mmm worker run-node REQUEST`:
// one Slurm job per node execution, with the node type's threads and memory
// (NodeSpec::resources), listed by squeue like any job. srun asks for the
// allocation at once (no wait for the scheduler's next pass, unlike sbatch:
// docs/experiments/slurm-submission.md) and returns when the job has ended;
// the runner then reads the result the worker wrote. A job that ends without
// a result (cancelled with scancel, out of memory, out of time, a failed
// node) becomes a failed execution whose error gives Slurm's job state and
// reason; the next run submits it again. srun is the runner's child with a
// parent-death signal: a killed runner cancels its jobs.
//
// Assumes a file system shared by the coordinator and the cluster's nodes,
// at the same paths (the study folder, the root's shared store and the mmm
// executable), and that the coordinator's host may run srun (a login node).

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
  // Extra srun arguments for every job, e.g. {"--partition=short",
  // "--account=lab", "--time=30"}.
  std::vector<std::string> srun_arguments;
};

// Runs `job` as a Slurm job and waits for it; never throws (a failure to
// submit is the Completion's error). Its folder is
// `scratch_root`/slurm-<execution id>-<node>: request.json, slurm.log (the
// worker's output, kept when the job failed), result.json.
Completion execute_on_slurm(const Job& job, const std::filesystem::path& artifacts,
                            const std::optional<std::filesystem::path>& pool,
                            const std::filesystem::path& scratch_root, const SlurmOptions& options,
                            RunObserver* observer);

// A job Slurm still remembers (squeue --states=all: until MinJobAge after
// its end), found by its name and comment.
struct SlurmJobState {
  std::string id;
  std::string state;   // PENDING, RUNNING, COMPLETED, CANCELLED, FAILED, ...
  std::string reason;  // squeue's reason, e.g. PartitionDown, None
};
std::optional<SlurmJobState> find_slurm_job(const std::string& name, const std::string& comment);

}  // namespace mmm::workflow

#pragma once
// Running a study: every node whose cache key has no result runs, on a
// thread pool, as soon as the nodes it takes outputs from are done; the rest
// is reused.
//
//   refresh file inputs; mark executions a dead runner left 'running' as
//   'interrupted'; delete its temporary artifacts and scratch folders
//   ready <- nodes whose inputs are all study inputs
//   while ready or running:
//     for n in ready: key <- cache_key(type, version, params, input hashes)
//                     a 'done' execution with that key and its artifacts? reuse
//                     manual node without a result? -> waiting
//                     else record 'running' and hand n to the pool
//     wait for a node to finish; record done (outputs) or failed (error);
//     its dependents whose inputs are now all available become ready
//   export the workflow's outputs; record the run
//
// Crash safety: a node's outputs are artifacts (artifact_store.h) flushed to
// disk before its 'done' row is committed (one syncfs per group commit, the
// store being in deferred-sync mode during the run), rows are committed in
// order, and a 'done' row is the only thing that makes a result reusable, so a run killed at any
// instant leaves a study whose next run redoes exactly the unfinished work.
// Rows are committed in groups (at most `commit_interval` after the first
// uncommitted one, and always at the end), which keeps the per-node overhead
// far below a millisecond; a crash loses at most that much finished work.
//
// A failing node (exception, missing output) is recorded failed with its
// error; nodes that need it are blocked, independent branches finish.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "workflow/run/run_observer.h"
#include "workflow/run/slurm_executor.h"
#include "workflow/store/study_lock.h"
#include "workflow/study/study.h"

namespace mmm::workflow {

enum class Executor { kLocal, kSlurm };

struct RunOptions {
  // Nodes run at the same time (threads); at least 1.
  int jobs = 1;
  // Who runs it, recorded with the run.
  Provenance provenance;
  // Progress and log events; nullptr: none.
  RunObserver* observer = nullptr;
  // Longest delay between a node finishing and its record being committed.
  std::chrono::milliseconds commit_interval{200};
  // Run nodes that crashed the process before with the same cache key
  // (normally they are reported as failed: crash_records.h).
  bool retry_crashed = false;
  // Where nodes run: in this process's worker threads, or as Slurm jobs
  // (slurm_executor.h; `jobs` is then how many jobs are out at once).
  // Manual nodes are tasks either way.
  Executor executor = Executor::kLocal;
  SlurmOptions slurm{};
};

enum class RunOutcome {
  kDone,     // every node has a current result; outputs exported
  kWaiting,  // nothing failed, but a manual node waits for a person
  kFailed,   // at least one node failed (or has invalid parameters)
};
std::string_view run_outcome_name(RunOutcome outcome);

struct RunSummary {
  std::int64_t run_id = 0;
  RunOutcome outcome = RunOutcome::kDone;
  std::vector<std::string> executed;  // ran and finished ('done'), in finishing order
  std::vector<std::string> cached;    // reused
  std::vector<std::string> failed;    // ran and failed, or invalid parameters
  std::vector<std::string> waiting;   // manual nodes without a result
  std::vector<std::string> blocked;   // not reached: behind a failed or waiting node
  std::vector<std::string> input_changes;
  std::vector<std::string> exported;  // outputs (re)written to outputs/
  double seconds = 0;
};

// Runs the study; `lock` proves the caller holds the study's runner lock.
// Throws IoError/SqliteError only for store failures (disk full, database
// damaged); node failures are part of the summary.
RunSummary run_study(Study& study, const StudyLock& lock, const RunOptions& options);

}  // namespace mmm::workflow

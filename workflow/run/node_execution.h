#pragma once
// One node execution, as the runner's worker threads do it and as a worker
// process on a cluster does it (`mmm worker run-node`, slurm_executor.h):
// inputs checked against their hashes, the node run in its scratch folder,
// its outputs stored, its log kept. Nothing here touches the study
// database: the runner records the Completion.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "workflow/node_context.h"
#include "workflow/node_registry.h"
#include "workflow/run/run_observer.h"
#include "workflow/store/artifact_store.h"
#include "workflow/study/execution_records.h"

namespace mmm::workflow {

// What a worker hands back when a node finishes.
struct Completion {
  std::string node;
  std::int64_t execution_id = 0;
  std::map<std::string, OutputArtifact> outputs;
  std::string error;  // empty: success
  std::vector<LogLine> logs;
  double seconds = 0;
};

// A node handed to the pool.
struct Job {
  std::string node;
  std::int64_t execution_id = 0;
  std::string cache_key;
  const NodeType* type = nullptr;
  std::map<std::string, ArtifactRef> inputs;
  std::map<std::string, ParamValue> params;
};

// Runs `job` in `scratch_root`/<execution id>-<node> (removed afterwards);
// stores what it writes in `artifacts`. While the node runs, `crash_marker`
// names it (crash_marker.h). Never throws: a failure is the Completion's
// error.
Completion execute(const Job& job, ArtifactStore& artifacts,
                   const std::filesystem::path& scratch_root,
                   const std::filesystem::path& crash_marker, RunObserver* observer);

}  // namespace mmm::workflow

#pragma once
// Where a study stands without running anything: for every node, in
// execution order, whether its result is cached, it will run, it waits for a
// person, it failed, or it is blocked behind another node, and why. `mmm
// status` and `mmm explain` print this; the scheduler uses the same pieces
// (resolve_inputs, key_parts_for, why_it_runs) so that what explain predicts
// is what run does.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "workflow/node_context.h"
#include "workflow/study/execution_records.h"
#include "workflow/study/study.h"

namespace mmm::workflow {

enum class NodeState {
  kCached,   // a result with the current cache key exists: reused
  kPending,  // inputs are available and no result matches: it will run
  kFailed,   // its last attempt with the current key failed (it runs again)
  kWaiting,  // a manual node whose inputs are ready: waits for a person
  kBlocked,  // an upstream node has no current result yet
  kInvalid,  // its parameters are invalid (a study override the spec rejects)
};
std::string_view node_state_name(NodeState state);

struct NodePlan {
  const NodeInstance* node = nullptr;
  const NodeType* type = nullptr;
  NodeState state = NodeState::kBlocked;
  std::optional<CacheKeyParts> key_parts;  // known unless blocked or invalid
  std::string cache_key;                   // idem
  std::optional<ExecutionRecord> result;   // kCached: the reused execution
  std::optional<ExecutionRecord> last;     // the node's latest execution, if any
  std::vector<std::string> blocked_by;     // kBlocked: upstream nodes without a result
  std::string reason;                      // one sentence on why it is in this state
};

struct StudyPlan {
  std::vector<NodePlan> nodes;             // execution order
  std::vector<std::string> input_changes;  // refreshed file inputs (see refresh_file_inputs)

  [[nodiscard]] const NodePlan* find(std::string_view node) const;
  [[nodiscard]] int count(NodeState state) const;
};

// Evaluates the study's state. Re-imports changed input files first (that is
// a write: call it only under the study lock, or pass refresh = false to see
// the state as last recorded).
StudyPlan plan_study(Study& study, bool refresh_inputs);

// The artifacts a node's inputs are connected to: each connected input port
// -> its artifact, from the available outputs of upstream nodes (node -> port
// -> artifact) and the study inputs. `missing` receives the upstream nodes
// (or "study.NAME") that have no value yet.
std::map<std::string, ArtifactRef> resolve_inputs(
    const NodeInstance& node, const NodeSpec& spec,
    const std::map<std::string, std::map<std::string, OutputArtifact>>& available,
    const std::map<std::string, StudyInputRecord>& inputs, const ArtifactStore& artifacts,
    std::vector<std::string>& missing);

// The cache key parts of a node (effective parameters + input hashes). Throws
// InvalidInputError when the given parameters are invalid.
CacheKeyParts key_parts_for(const NodeSpec& spec, const std::map<std::string, ParamValue>& given,
                            const std::map<std::string, ArtifactRef>& inputs);

// Whether every output artifact of `record` is in the store.
bool outputs_present(const ExecutionRecord& record, const ArtifactStore& artifacts);

// Why a node without a reusable result runs, as one sentence: "first run",
// "parameter 'target_faces' changed from 5000 to 2000; input 'mesh' changed
// (...)", "its earlier result is missing from the artifact store", "the last
// attempt failed: ...".
std::string why_it_runs(const std::optional<ExecutionRecord>& last_done,
                        const std::optional<ExecutionRecord>& last, const CacheKeyParts& now,
                        const std::string& cache_key);

}  // namespace mmm::workflow

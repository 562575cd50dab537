#include "workflow/run/study_plan.h"

#include <algorithm>

#include "core/errors.h"
#include "workflow/definition/workflow_graph.h"
#include "workflow/run/crash_marker.h"
#include "workflow/study/crash_records.h"

namespace mmm::workflow {
namespace {

std::string join_sentences(const std::vector<std::string>& parts) {
  std::string text;
  for (const std::string& part : parts) text += (text.empty() ? "" : "; ") + part;
  return text;
}

// A crash recorded for the node with this key, or one its marker names (the
// run that reads the marker has not happened yet).
std::optional<CrashRecord> crash_of(Study& study, const std::vector<MarkedCrash>& marked,
                                    const std::string& node, const std::string& cache_key) {
  std::optional<CrashRecord> crash = find_crash(study.database(), node, cache_key);
  if (crash) return crash;
  for (const MarkedCrash& mark : marked) {
    if (mark.node == node && mark.cache_key == cache_key) {
      return CrashRecord{node, cache_key, mark.signal, "at the next run"};
    }
  }
  return std::nullopt;
}

}  // namespace

std::string_view node_state_name(NodeState state) {
  switch (state) {
    case NodeState::kCached:
      return "cached";
    case NodeState::kPending:
      return "pending";
    case NodeState::kFailed:
      return "failed";
    case NodeState::kWaiting:
      return "waiting";
    case NodeState::kBlocked:
      return "blocked";
    case NodeState::kInvalid:
      return "invalid";
  }
  return "unknown";
}

const NodePlan* StudyPlan::find(std::string_view node) const {
  const auto it =
      std::ranges::find_if(nodes, [&](const NodePlan& plan) { return plan.node->id == node; });
  return it == nodes.end() ? nullptr : &*it;
}

int StudyPlan::count(NodeState state) const {
  return static_cast<int>(
      std::ranges::count_if(nodes, [&](const NodePlan& plan) { return plan.state == state; }));
}

std::map<std::string, ArtifactRef> resolve_inputs(
    const NodeInstance& node, const NodeSpec& spec,
    const std::map<std::string, std::map<std::string, OutputArtifact>>& available,
    const std::map<std::string, StudyInputRecord>& inputs, const ArtifactStore& artifacts,
    std::vector<std::string>& missing) {
  std::map<std::string, ArtifactRef> refs;
  for (const auto& [port, connection] : node.inputs) {
    const PortSpec* port_spec = spec.find_input(port);
    if (port_spec == nullptr) continue;  // rejected by validation
    const Reference& source = connection.source;
    if (source.is_study()) {
      const auto input = inputs.find(source.port);
      if (input == inputs.end()) {
        missing.push_back(source.text());
        continue;
      }
      refs[port] = {port_spec->type, input->second.hash, artifacts.path_of(input->second.hash)};
      continue;
    }
    const auto upstream = available.find(source.node);
    if (upstream == available.end()) {
      if (std::ranges::find(missing, source.node) == missing.end()) missing.push_back(source.node);
      continue;
    }
    const auto output = upstream->second.find(source.port);
    if (output == upstream->second.end()) {
      throw InvalidInputError("node '" + source.node + "' recorded no output '" + source.port +
                              "' (needed by '" + node.id + "'); re-run it");
    }
    refs[port] = {output->second.type, output->second.hash, artifacts.path_of(output->second.hash)};
  }
  return refs;
}

CacheKeyParts key_parts_for(const NodeSpec& spec, const std::map<std::string, ParamValue>& given,
                            const std::map<std::string, ArtifactRef>& inputs) {
  CacheKeyParts parts;
  parts.node_type = spec.name();
  parts.version = spec.version();
  parts.params = effective_params(spec, given);
  for (const auto& [port, ref] : inputs) parts.input_hashes[port] = ref.hash;
  return parts;
}

bool outputs_present(const ExecutionRecord& record, const ArtifactStore& artifacts) {
  return std::ranges::all_of(
      record.outputs, [&](const auto& output) { return artifacts.contains(output.second.hash); });
}

std::string why_it_runs(const std::optional<ExecutionRecord>& last_done,
                        const std::optional<ExecutionRecord>& last, const CacheKeyParts& now,
                        const std::string& cache_key) {
  if (last && last->cache_key == cache_key && last->status == ExecutionStatus::kFailed) {
    return "its last attempt with these inputs and parameters failed (" + last->error +
           "); it runs again";
  }
  if (last && last->cache_key == cache_key && last->status == ExecutionStatus::kInterrupted) {
    return "its last attempt was interrupted; it runs again";
  }
  if (!last_done) return "first run (no earlier result)";
  if (last_done->cache_key == cache_key) {
    return "its earlier result is missing from the artifact store; it runs again";
  }
  const std::vector<std::string> changes = describe_key_changes(last_done->key_parts, now);
  if (changes.empty()) return "its cache key changed";
  return join_sentences(changes);
}

StudyPlan plan_study(Study& study, bool refresh_inputs) {
  StudyPlan plan;
  if (refresh_inputs) plan.input_changes = study.refresh_file_inputs();
  const std::map<std::string, StudyInputRecord> inputs = study.inputs();
  const WorkflowDefinition& workflow = study.workflow();
  std::map<std::string, std::map<std::string, OutputArtifact>> available;
  const std::vector<MarkedCrash> marked_crashes = read_crash_marker(study.crash_marker());
  for (const std::string& id : topological_order(workflow)) {
    NodePlan node_plan;
    node_plan.node = workflow.find_node(id);
    node_plan.type = study.registry().find(node_plan.node->type);
    node_plan.last = last_execution(study.database(), id);
    const NodeSpec& spec = node_plan.type->spec;
    const std::map<std::string, ArtifactRef> refs = resolve_inputs(
        *node_plan.node, spec, available, inputs, study.artifacts(), node_plan.blocked_by);
    if (!node_plan.blocked_by.empty()) {
      node_plan.state = NodeState::kBlocked;
      node_plan.reason = "waits for " + join_sentences(node_plan.blocked_by);
      plan.nodes.push_back(std::move(node_plan));
      continue;
    }
    try {
      node_plan.key_parts = key_parts_for(spec, study.given_params(*node_plan.node), refs);
    } catch (const InvalidInputError& e) {
      node_plan.state = NodeState::kInvalid;
      node_plan.reason = e.what();
      plan.nodes.push_back(std::move(node_plan));
      continue;
    }
    node_plan.cache_key = cache_key(*node_plan.key_parts);
    const std::string* manual_node = spec.is_manual() ? &node_plan.node->id : nullptr;
    std::optional<ExecutionRecord> result =
        find_result(study.database(), node_plan.cache_key, manual_node);
    if (result && outputs_present(*result, study.artifacts())) {
      node_plan.state = NodeState::kCached;
      node_plan.reason =
          result->manual
              ? "result submitted by " + result->submitted_by + " at " + result->finished_at
              : "execution #" + std::to_string(result->id) + " of " +
                    (result->node == id ? "this node" : "node '" + result->node + "'") + " at " +
                    result->finished_at +
                    " had the same cache key (same type, version, parameters "
                    "and input content)";
      available[id] = result->outputs;
      node_plan.result = std::move(result);
    } else if (spec.is_manual()) {
      node_plan.state = NodeState::kWaiting;
      node_plan.reason = "waits for a person to provide its result (manual node)";
    } else if (std::optional<CrashRecord> crash =
                   crash_of(study, marked_crashes, id, node_plan.cache_key)) {
      node_plan.state = NodeState::kFailed;
      node_plan.reason = crash_error(*crash);
    } else {
      const bool failed_before = node_plan.last &&
                                 node_plan.last->cache_key == node_plan.cache_key &&
                                 node_plan.last->status == ExecutionStatus::kFailed;
      node_plan.state = failed_before ? NodeState::kFailed : NodeState::kPending;
      node_plan.reason = why_it_runs(last_done_execution(study.database(), id), node_plan.last,
                                     *node_plan.key_parts, node_plan.cache_key);
    }
    plan.nodes.push_back(std::move(node_plan));
  }
  return plan;
}

}  // namespace mmm::workflow

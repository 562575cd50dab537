#pragma once
// A node execution handed to another process (a worker on a cluster node:
// `mmm worker run-node REQUEST`, slurm_executor.h) and its result handed
// back. The worker reads its inputs from the study's artifact store and
// writes its outputs there (the store is safe for concurrent writers); it
// never opens the study database, which only the coordinating runner
// writes.
//
// request.json:
//   {"format": "mmm-node-request", "version": 1, "node": "wrap",
//    "node_type": "wrap_muscles", "execution_id": 12, "cache_key": "<hex>",
//    "inputs": {"atlas": {"type": "Atlas", "hash": "<hex>"}, ...},
//    "params": {"name": <tagged value, cache_key.h>, ...},
//    "artifacts": "/abs/study/artifacts", "pool": "/abs/root/.mmm-store" (optional),
//    "scratch": "/abs/scratch folder", "result": "/abs/result.json"}
// result.json:
//   {"format": "mmm-node-result", "version": 1, "node": "wrap", "execution_id": 12,
//    "outputs": {"port": {"type": "File", "hash": "<hex>"}}, "error": "",
//    "logs": [{"time": "...", "level": "info", "message": "..."}], "seconds": 1.5,
//    "host": "node07"}

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "workflow/node_registry.h"
#include "workflow/run/node_execution.h"

namespace mmm::workflow {

struct NodeRequest {
  Job job;  // job.type resolved from the registry when read
  std::filesystem::path artifacts;
  std::optional<std::filesystem::path> pool;
  std::filesystem::path scratch;
  std::filesystem::path result;
};

std::string node_request_text(const NodeRequest& request);

// Throws IoError naming `source` and the field: not JSON, wrong format, an
// unknown node type, a bad hash, a relative path.
NodeRequest node_request_from_text(std::string_view text, const std::filesystem::path& source,
                                   const NodeRegistry& registry);

std::string completion_text(const Completion& completion, const std::string& host);

// Throws IoError naming `source` and the field.
Completion completion_from_text(std::string_view text, const std::filesystem::path& source);

// The worker's side: runs the request's node (node_execution.h) against the
// study's store and writes the completion to request.result (atomically).
// Returns it. Throws only when the result cannot be written.
Completion run_node_request(const NodeRequest& request);

}  // namespace mmm::workflow

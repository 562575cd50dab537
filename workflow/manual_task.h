#pragma once
// What a manual node type's tasks are made of, registered with the node type
// (node_registry.h) so that the worklist, the audit trail, the operator
// commands and the web server handle every manual node alike, without
// knowing any of them by name:
//
//   request   (key parts, artifact store) -> the task's request: what the
//             operator is shown (JSON; its "kind", e.g. "landmarks", tells a
//             client which view to show; "images" maps each view to the
//             SHA-256 of the image shown, recorded in the audit trail)
//   evaluate  (request, submission) -> ManualEvaluation: the reasons to
//             reject the submission, or the values to show and audit and the
//             bytes of every output port of the node (its result once
//             accepted). Anything malformed is a reason, never an exception.
//   preview   as evaluate, for a submission being composed (nothing is
//             recorded); empty: evaluate is used.
//   submission_fields  the top-level fields of a submission: a web request
//             body carries them beside its own fields (e.g. "reason").
//
// A node type registered as manual without a complete behaviour (kind,
// request, evaluate, at least one submission field) is refused at
// registration, and so is a computing node type with one.

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "workflow/port_type.h"
#include "workflow/store/artifact_store.h"
#include "workflow/study/cache_key.h"

namespace mmm::workflow {

struct ManualOutput {
  PortType type = PortType::kFile;
  std::string bytes;
};

// What a manual node type makes of a person's submission: the reasons to
// reject it (none: acceptable), the values to show and audit, and the bytes
// of each output port recorded as the node's result once accepted.
// NOLINTNEXTLINE(bugprone-exception-escape): nlohmann::json's noexcept move only asserts
struct ManualEvaluation {
  std::vector<std::string> reasons;
  nlohmann::json values;
  std::map<std::string, ManualOutput> outputs;  // port -> value (empty when rejected)
};

using TaskRequestFunction =
    std::function<nlohmann::json(const CacheKeyParts& parts, const ArtifactStore& artifacts)>;
using SubmissionFunction = std::function<ManualEvaluation(const nlohmann::json& request,
                                                          const nlohmann::json& submission)>;

struct ManualTaskBehaviour {
  std::string kind;  // the request's "kind"
  TaskRequestFunction request;
  SubmissionFunction evaluate;
  SubmissionFunction preview;  // empty: evaluate
  std::vector<std::string> submission_fields;

  // Whether anything is set (a computing node type has nothing).
  [[nodiscard]] bool empty() const {
    return kind.empty() && !request && !evaluate && !preview && submission_fields.empty();
  }
  // Whether kind, request, evaluate and the submission fields are all set.
  [[nodiscard]] bool complete() const {
    return !kind.empty() && request && evaluate && !submission_fields.empty();
  }
};

}  // namespace mmm::workflow

#pragma once
// A task behaviour for test manual node types whose tasks are never opened
// or evaluated: a manual node type must be registered with one
// (workflow/manual_task.h). Its request is empty and every submission is
// rejected.

#include "workflow/manual_task.h"

namespace mmm::test {

inline workflow::ManualTaskBehaviour stub_task_behaviour() {
  workflow::ManualTaskBehaviour task;
  task.kind = "test";
  task.request = [](const workflow::CacheKeyParts&, const workflow::ArtifactStore&) {
    return nlohmann::json::object();
  };
  task.evaluate = [](const nlohmann::json&, const nlohmann::json&) {
    workflow::ManualEvaluation evaluation;
    evaluation.reasons.emplace_back("test node types take no submission");
    return evaluation;
  };
  task.submission_fields = {"values"};
  return task;
}

}  // namespace mmm::test

#pragma once
// mmm status and mmm explain: where a study stands and why, as text for
// people and JSON for scripts.

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "workflow/node_registry.h"
#include "workflow/study/study.h"

namespace mmm::app {

// What `mmm status --json` prints: inputs, each node's state, reason, last
// execution (times, cache key) and the last run.
nlohmann::json study_status(workflow::Study& study);

void register_study_report_commands(CLI::App& app, const workflow::NodeRegistry& registry);

}  // namespace mmm::app

#pragma once
// mmm status and mmm explain: where a study stands and why, as text for
// people and JSON for scripts.

#include <CLI/CLI.hpp>

#include "workflow/node_registry.h"

namespace mmm::app {

void register_study_report_commands(CLI::App& app, const workflow::NodeRegistry& registry);

}  // namespace mmm::app

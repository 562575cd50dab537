#pragma once
// Registration of the subcommand groups of the `mmm` executable. Each group
// lives in its own file and runs its work inside CLI11 callbacks.

#include <CLI/CLI.hpp>

namespace mmm::app {

// mmm mesh info|convert|decimate|survey
void register_mesh_commands(CLI::App& app);

}  // namespace mmm::app

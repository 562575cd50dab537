#include "app/commands/commands.h"

namespace mmm::app {

void register_mesh_commands(CLI::App& app) {
  auto* mesh = app.add_subcommand("mesh", "Inspect, convert and simplify surface meshes");
  mesh->require_subcommand(1);
}

}  // namespace mmm::app

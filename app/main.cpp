// mmm: patient-specific moving musculoskeletal models of the lower limb.
// Entry point: parses the subcommand and maps errors to exit codes
//   0 success, 1 the command failed (message names file/field and a hint),
//   2 the command line itself is wrong, 3 the study waits for a manual task,
//   4 another runner holds the study (see app/commands/commands.h).

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <string>

#include "app/commands/commands.h"
#include "core/errors.h"
#include "nodes/registry.h"

namespace {

int run(int argc, char** argv) {
  CLI::App app{
      "mmm - patient-specific moving musculoskeletal models of the lower limb.\n"
      "Run 'mmm COMMAND --help' for the options of a command."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("mmm ") + MMM_VERSION);
  mmm::app::register_mesh_commands(app);
  mmm::app::register_atlas_commands(app);
  mmm::app::register_patient_commands(app);
  mmm::app::register_overlay_commands(app);
  mmm::app::register_calibrate_commands(app);
  const mmm::workflow::NodeRegistry registry = mmm::nodes::make_node_registry();
  mmm::app::register_workflow_commands(app, registry);
  mmm::app::register_study_commands(app, registry);
  mmm::app::register_cohort_commands(app, registry);
  mmm::app::register_worker_commands(app, registry);
  mmm::app::register_task_commands(app, registry);
  mmm::app::register_report_commands(app, registry);
  mmm::app::register_serve_commands(app, registry);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Help and version requests exit 0; every other parse problem is a usage
    // error: CLI11 prints it, we exit 2.
    return app.exit(e) == 0 ? 0 : 2;
  }
  return mmm::app::exit_code();
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const mmm::IoError& e) {
    std::cerr << "mmm: error: " << e.what() << '\n';
  } catch (const mmm::InvalidInputError& e) {
    std::cerr << "mmm: invalid input: " << e.what() << '\n';
  } catch (const std::exception& e) {
    std::cerr << "mmm: error: " << e.what() << '\n';
  } catch (...) {
    std::cerr << "mmm: error: unknown failure\n";
  }
  return 1;
}

// mmm: patient-specific moving musculoskeletal models of the lower limb.
// Entry point: parses the subcommand and maps errors to exit codes
//   0 success, 1 the command failed (message names file/field and a hint),
//   2 the command line itself is wrong.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <iostream>

#include "app/commands/commands.h"
#include "core/errors.h"

int main(int argc, char** argv) {
  CLI::App app{
      "mmm - patient-specific moving musculoskeletal models of the lower limb\n"
      "Run 'mmm COMMAND --help' for the options of a command."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("mmm ") + MMM_VERSION);
  mmm::app::register_mesh_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const mmm::IoError& e) {
    std::cerr << "mmm: error: " << e.what() << '\n';
    return 1;
  } catch (const mmm::InvalidInputError& e) {
    std::cerr << "mmm: invalid input: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "mmm: error: " << e.what() << '\n';
    return 1;
  }
  return 0;
}

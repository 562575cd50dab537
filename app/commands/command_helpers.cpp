// Small helpers shared by the command groups.

#include "app/commands/commands.h"
#include "core/errors.h"
#include "mmm_git_revision.h"

namespace mmm::app {

workflow::Provenance this_program() { return {MMM_VERSION, MMM_GIT_REVISION}; }

std::filesystem::path this_executable_path() {
  std::error_code error;
  std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) throw IoError("/proc/self/exe", "cannot find this program: " + error.message());
  return self;
}

std::pair<std::string, std::string> split_assignment(const std::string& text,
                                                     const std::string& what) {
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw InvalidInputError(what + " '" + text + "' is not of the form NAME=VALUE");
  }
  return {text.substr(0, equals), text.substr(equals + 1)};
}

}  // namespace mmm::app

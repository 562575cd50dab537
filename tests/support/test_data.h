#pragma once
// Helpers shared by the test suites: where the real data and the build live,
// and scratch folders that clean up after themselves.

#include <filesystem>
#include <string>

namespace mmm::test {

// ../shared/data as configured at build time (CMake MMM_DATA_DIR). A test that
// needs it fails (never skips) when it is missing: CI always has it beside us.
std::filesystem::path data_dir();

// OpenSim's gait2392 example under data_dir(): the generic model, and the
// Pipelines folder of subject01's trials, setups and reference results.
inline std::filesystem::path gait2392_model() {
  return data_dir() / "gait2392" / "gait2392_thelen2003muscle.osim";
}
inline std::filesystem::path gait2392_pipelines() { return data_dir() / "gait2392" / "Pipelines"; }

// The project's source and build folders.
std::filesystem::path source_dir();
std::filesystem::path binary_dir();

// Path to build/bin/mmm, for tests that run the command line.
std::filesystem::path mmm_executable();

// Result of running the mmm executable.
struct CommandResult {
  int exit_code = -1;  // -1 when it did not exit normally
  std::string out;     // stdout
  std::string err;     // stderr
};

// Runs `[environment] build/bin/mmm arguments` through the shell (arguments
// are not quoted for you), capturing stdout and stderr apart.
CommandResult run_mmm(const std::string& arguments, const std::string& environment = {});

// A fresh empty folder under the system temp dir, removed when destroyed.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& label);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const {
    return path_ / name;
  }

 private:
  std::filesystem::path path_;
};

// Whole content of a file; throws when it cannot be read.
std::string read_text(const std::filesystem::path& path);

// Writes bytes to a file (creating parent folders); returns the path.
std::filesystem::path write_file(const std::filesystem::path& path, const std::string& bytes);

}  // namespace mmm::test

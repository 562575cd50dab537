#include "tests/support/test_data.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>

namespace mmm::test {

std::filesystem::path data_dir() {
  std::filesystem::path dir = std::filesystem::weakly_canonical(MMM_DATA_DIR);
  if (!std::filesystem::is_directory(dir / "vhf") ||
      !std::filesystem::is_directory(dir / "gait2392")) {
    throw std::runtime_error("shared data not found at " + dir.string() +
                             " (expected vhf/ and gait2392/); configure with "
                             "-DMMM_DATA_DIR=... or place ../shared beside the checkout");
  }
  return dir;
}

std::filesystem::path source_dir() { return MMM_SOURCE_DIR; }
std::filesystem::path binary_dir() { return MMM_BINARY_DIR; }
std::filesystem::path mmm_executable() { return binary_dir() / "bin" / "mmm"; }

ScratchDir::ScratchDir(const std::string& label) {
  std::random_device device;
  const auto base = std::filesystem::temp_directory_path();
  for (int attempt = 0; attempt < 100; ++attempt) {
    auto candidate = base / ("mmm-test-" + label + "-" + std::to_string(device()));
    if (std::filesystem::create_directory(candidate)) {
      path_ = candidate;
      return;
    }
  }
  throw std::runtime_error("could not create a scratch folder under " + base.string());
}

ScratchDir::~ScratchDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

CommandResult run_mmm(const std::string& arguments, const std::string& environment) {
  const ScratchDir dir("cli");
  const auto err_file = dir / "stderr.txt";
  const std::string command =
      environment + " " + mmm_executable().string() + " " + arguments + " 2>" + err_file.string();
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {};
  CommandResult result;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    result.out.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.err = read_text(err_file);
  return result;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("could not read " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::filesystem::path write_file(const std::filesystem::path& path, const std::string& bytes) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("could not write " + path.string());
  return path;
}

}  // namespace mmm::test

#pragma once
// Typed exceptions thrown by core/ kernels. Every message says what is wrong,
// where (file, field, index) and, when there is one, a hint at the fix. Nodes
// and the CLI catch these at their boundary; kernels never abort on user data.

#include <filesystem>
#include <stdexcept>
#include <string>

namespace mmm {

// A file could not be read or written, or its content is not what its format
// promises. what() starts with the path.
class IoError : public std::runtime_error {
 public:
  IoError(const std::filesystem::path& path, const std::string& problem)
      : std::runtime_error(path.string() + ": " + problem), path_(path) {}
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Data handed to a kernel violates its contract (NaN coordinates, face index
// out of range, empty mesh where one is required, ...).
class InvalidInputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// A numerical solver did not reach a usable answer; what() carries its summary.
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mmm

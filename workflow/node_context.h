#pragma once
// What a running node sees: its resolved inputs (artifacts in the store),
// its parameters, a scratch folder, and channels for outputs, progress and
// log lines. The executor builds one per execution; a node never touches the
// study store directly, so every node is restartable by construction.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <string_view>

#include "workflow/node_spec.h"

namespace mmm::workflow {

// A stored value: its type, the SHA-256 of its bytes, and where the bytes are.
struct ArtifactRef {
  PortType type;
  std::string hash;            // 64 lowercase hex
  std::filesystem::path path;  // the blob in the study's artifact store (read-only)
};

enum class LogLevel { kDebug, kInfo, kWarning, kError };

class NodeContext {
 public:
  // Channels the executor provides. `store` puts bytes into the artifact
  // store and returns their hash; `store_file` does the same for a file
  // (streamed, the file is left in place).
  struct Channels {
    std::function<std::string(std::string_view bytes)> store;
    std::function<std::string(const std::filesystem::path& file)> store_file;
    std::function<void(std::int64_t done, std::int64_t total, std::string_view what)> progress;
    std::function<void(LogLevel level, std::string_view message)> log;
  };

  NodeContext(const NodeSpec& spec, std::map<std::string, ArtifactRef> inputs,
              std::map<std::string, ParamValue> params, std::filesystem::path scratch_dir,
              Channels channels);

  [[nodiscard]] const NodeSpec& spec() const { return *spec_; }

  // Inputs. input() throws InvalidInputError for an unknown or unconnected
  // port; input_bytes() reads the whole artifact.
  [[nodiscard]] bool has_input(std::string_view port) const;
  [[nodiscard]] const ArtifactRef& input(std::string_view port) const;
  [[nodiscard]] std::string input_bytes(std::string_view port) const;

  // Parameters, by their declared type (defaults already applied).
  [[nodiscard]] double number(std::string_view name) const;
  [[nodiscard]] std::int64_t integer(std::string_view name) const;
  [[nodiscard]] const std::string& text(std::string_view name) const;  // kString and kEnum
  [[nodiscard]] bool flag(std::string_view name) const;
  [[nodiscard]] const std::map<std::string, ParamValue>& params() const { return params_; }

  // Outputs: every declared output must be set exactly once before run()
  // returns; the executor checks.
  void set_output(std::string_view port, std::string_view bytes);
  void set_output_file(std::string_view port, const std::filesystem::path& file);
  [[nodiscard]] const std::map<std::string, ArtifactRef>& outputs() const { return outputs_; }

  // A private, empty folder for temporary files, deleted after the run.
  [[nodiscard]] const std::filesystem::path& scratch_dir() const { return scratch_dir_; }

  void progress(std::int64_t done, std::int64_t total, std::string_view what = {}) const;
  void log(LogLevel level, std::string_view message) const;
  void info(std::string_view message) const { log(LogLevel::kInfo, message); }
  void warn(std::string_view message) const { log(LogLevel::kWarning, message); }

 private:
  const ParamValue& param(std::string_view name, ParamType expected) const;
  const PortSpec& output_port(std::string_view port);

  const NodeSpec* spec_;
  std::map<std::string, ArtifactRef> inputs_;
  std::map<std::string, ParamValue> params_;
  std::filesystem::path scratch_dir_;
  Channels channels_;
  std::map<std::string, ArtifactRef> outputs_;
};

}  // namespace mmm::workflow

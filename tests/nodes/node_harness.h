#pragma once
// Runs a node type the way the executor does, without the study store:
// artifacts are files in a temporary folder named by a hash of their bytes
// (std::hash here; the real store uses SHA-256), each run gets an empty
// scratch folder, and log lines are kept for inspection.

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <iomanip>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/test_data.h"
#include "workflow/node_context.h"

namespace mmm::nodes::test {

class NodeHarness {
 public:
  NodeHarness() : dir_("node-harness") { std::filesystem::create_directories(dir_ / "store"); }

  // Stores bytes as an artifact of `type`.
  workflow::ArtifactRef add(workflow::PortType type, const std::string& bytes) {
    const std::string hash = store(bytes);
    return {type, hash, blob(hash)};
  }
  workflow::ArtifactRef add_file(workflow::PortType type, const std::filesystem::path& file) {
    return add(type, mmm::test::read_text(file));
  }

  // Runs Node::run and returns its outputs with their paths filled in.
  // Fails the test when an output was left unset.
  template <class Node>
  std::map<std::string, workflow::ArtifactRef> run(
      std::map<std::string, workflow::ArtifactRef> inputs,
      std::map<std::string, workflow::ParamValue> params = {}) {
    const workflow::NodeSpec spec = Node::spec();
    const std::filesystem::path scratch = dir_ / ("scratch" + std::to_string(runs_++));
    std::filesystem::create_directories(scratch);
    workflow::NodeContext::Channels channels;
    channels.store = [this](std::string_view bytes) { return store(bytes); };
    channels.store_file = [this](const std::filesystem::path& file) {
      return store(mmm::test::read_text(file));
    };
    channels.log = [this](workflow::LogLevel, std::string_view message) {
      log_.emplace_back(message);
    };
    workflow::NodeContext context(spec, std::move(inputs), std::move(params), scratch, channels);
    Node::run(context);
    std::filesystem::remove_all(scratch);
    std::map<std::string, workflow::ArtifactRef> outputs = context.outputs();
    for (auto& [port, ref] : outputs) ref.path = blob(ref.hash);
    for (const workflow::PortSpec& port : spec.outputs()) {
      EXPECT_EQ(outputs.count(port.name), 1U) << "output '" << port.name << "' was not set";
    }
    return outputs;
  }

  [[nodiscard]] const std::vector<std::string>& log() const { return log_; }
  [[nodiscard]] const std::filesystem::path& folder() const { return dir_.path(); }

 private:
  std::filesystem::path blob(const std::string& hash) const { return dir_ / "store" / hash; }

  std::string store(std::string_view bytes) {
    std::ostringstream hex;
    hex << std::hex << std::setw(16) << std::setfill('0') << std::hash<std::string_view>{}(bytes);
    std::string hash = hex.str();
    mmm::test::write_file(blob(hash), std::string(bytes));
    return hash;
  }

  mmm::test::ScratchDir dir_;
  int runs_ = 0;
  std::vector<std::string> log_;
};

}  // namespace mmm::nodes::test

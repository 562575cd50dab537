#include "core/bounded_yaml.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include <algorithm>
#include <map>
#include <sstream>
#include <string>
#include <system_error>

#include "core/file_bytes.h"

namespace mmm {
namespace {

// Counts the nodes and the nesting of each document as they would be with
// every alias replaced by a copy of the node it names.
class ExpandedSizeCheck : public YAML::EventHandler {
 public:
  explicit ExpandedSizeCheck(const YamlLimits& limits) : limits_(limits) {}

  // yaml-cpp 0.7 reads a stray ',' at the top level (a file of just ",")
  // as an empty document and starts the next one at the same place, without
  // end (found by fuzzing): a document that starts where the previous one
  // did is refused. The node limit holds for the whole text, so many small
  // documents cannot pass it either.
  void OnDocumentStart(const YAML::Mark& mark) override {
    if (documents_ > 0 && mark.pos == last_document_start_) {
      throw YAML::ParserException(mark,
                                  "the text cannot be read past this place (a stray ',' or "
                                  "another character that starts no YAML node?)");
    }
    ++documents_;
    last_document_start_ = mark.pos;
    anchored_.clear();
    open_.clear();
  }
  void OnDocumentEnd() override {}

  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { leaf(mark, anchor); }
  void OnScalar(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t anchor,
                const std::string& /*value*/) override {
    leaf(mark, anchor);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    for (const Collection& collection : open_) {
      if (collection.anchor == anchor) {
        throw YAML::ParserException(mark,
                                    "an alias names a node that contains it (the node would hold "
                                    "itself without end); hint: write the value out instead");
      }
    }
    const auto named = anchored_.find(anchor);
    if (named == anchored_.end()) {
      throw YAML::ParserException(mark, "an alias names an anchor that is not defined before it");
    }
    add(mark, named->second.nodes, named->second.height);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value /*style*/) override {
    start_collection(mark, anchor);
  }
  void OnSequenceEnd() override { end_collection(); }
  void OnMapStart(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value /*style*/) override {
    start_collection(mark, anchor);
  }
  void OnMapEnd() override { end_collection(); }

 private:
  // What a node stands for once expanded: its node count and its height
  // (0 for a scalar, 1 for a collection of scalars, ...).
  struct Expanded {
    std::size_t nodes = 0;
    std::size_t height = 0;
  };
  struct Collection {
    YAML::anchor_t anchor = YAML::NullAnchor;
    std::size_t nodes_before = 0;
    std::size_t child_height = 0;
  };

  void leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
    add(mark, 1, 0);
    if (anchor != YAML::NullAnchor) anchored_[anchor] = {1, 0};
  }

  // A node of `nodes` nodes and height `height` placed in the innermost open
  // collection.
  void add(const YAML::Mark& mark, std::size_t nodes, std::size_t height) {
    if (nodes > limits_.max_nodes - nodes_) {
      throw YAML::ParserException(
          mark, "with its aliases expanded the text holds more than " +
                    std::to_string(limits_.max_nodes) +
                    " nodes (an alias bomb?); hint: write repeated values out, or split the file");
    }
    nodes_ += nodes;
    if (open_.size() + height > limits_.max_depth) {
      throw YAML::ParserException(mark, "nested more than " + std::to_string(limits_.max_depth) +
                                            " levels deep (aliases expanded)");
    }
    if (!open_.empty()) open_.back().child_height = std::max(open_.back().child_height, height);
  }

  void start_collection(const YAML::Mark& mark, YAML::anchor_t anchor) {
    const std::size_t before = nodes_;
    add(mark, 1, 1);
    open_.push_back({anchor, before, 0});
  }

  void end_collection() {
    const Collection done = open_.back();
    open_.pop_back();
    const Expanded expanded{nodes_ - done.nodes_before, done.child_height + 1};
    if (done.anchor != YAML::NullAnchor) anchored_[done.anchor] = expanded;
    if (!open_.empty()) {
      open_.back().child_height = std::max(open_.back().child_height, expanded.height);
    }
  }

  const YamlLimits& limits_;
  std::map<YAML::anchor_t, Expanded> anchored_;
  std::vector<Collection> open_;
  std::size_t nodes_ = 0;
  std::size_t documents_ = 0;
  int last_document_start_ = -1;
};

YAML::Mark start_of_text() { return {}; }

void check_size(std::size_t bytes, const YamlLimits& limits) {
  if (bytes > limits.max_bytes) {
    throw YAML::ParserException(start_of_text(),
                                "the text is " + std::to_string(bytes) + " bytes; at most " +
                                    std::to_string(limits.max_bytes) + " are read");
  }
}

// YAML text has no NUL character (YAML 1.2, c-printable), and yaml-cpp's
// scanner can take minutes over one (found by fuzzing): refused first, with
// its line and column.
void check_no_nul(const std::string& text) {
  const std::size_t at = text.find('\0');
  if (at == std::string::npos) return;
  YAML::Mark mark;
  mark.pos = static_cast<int>(at);
  mark.line = static_cast<int>(
      std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  const std::size_t line_start = text.rfind('\n', at);
  mark.column = static_cast<int>(line_start == std::string::npos ? at : at - line_start - 1);
  throw YAML::ParserException(mark, "a NUL byte: this is not a YAML text file");
}

void check_limits(const std::string& text, const YamlLimits& limits) {
  check_size(text.size(), limits);
  check_no_nul(text);
  std::istringstream in(text);
  YAML::Parser parser(in);
  ExpandedSizeCheck check(limits);
  while (parser.HandleNextDocument(check)) {
  }
}

}  // namespace

std::vector<YAML::Node> load_all_yaml(std::string_view text, const YamlLimits& limits) {
  const std::string copy(text);
  check_limits(copy, limits);
  return YAML::LoadAll(copy);
}

YAML::Node load_yaml(std::string_view text, const YamlLimits& limits) {
  const std::string copy(text);
  check_limits(copy, limits);
  return YAML::Load(copy);
}

YAML::Node load_yaml_file(const std::filesystem::path& file, const YamlLimits& limits) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(file, error);
  if (error) throw YAML::BadFile(file.string());
  check_size(static_cast<std::size_t>(size), limits);
  return load_yaml(read_file_bytes(file, size), limits);
}

}  // namespace mmm

#pragma once
// YAML loading with limits checked before any node is built, for every YAML
// file mmm reads (workflows, schemas, atlas manifests and recipes, marker
// mappings).
//
// yaml-cpp shares an aliased node instead of copying it, so a few hundred
// bytes of nested aliases (`b: [*a, *a, *a]`, `c: [*b, *b, *b]`, ...) stand
// for billions of nodes that any walk over the tree visits, and an alias
// inside its own anchor (`a: &a [*a]`) makes a tree that contains itself:
// a walk never ends. The text is therefore first read as a stream of parse
// events in which every alias counts as the whole node it names; a document
// that names a node inside that node, or whose expanded size or depth passes
// the limits, is refused with yaml-cpp's ParserException at the offending
// place, so callers report it like any YAML syntax error (line, column).

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <filesystem>
#include <string_view>
#include <vector>

namespace mmm {

struct YamlLimits {
  // Size of the text; a file is refused before it is read.
  std::size_t max_bytes = std::size_t{16} << 20;
  // Nodes of the text (scalars, sequences, maps of all its documents) with
  // every alias expanded.
  std::size_t max_nodes = 2'000'000;
  // Nesting of sequences and maps, aliases expanded.
  std::size_t max_depth = 128;
};

// Every document of `text`, like YAML::LoadAll, once the limits hold.
// Throws YAML::ParserException (mark at the offending node) otherwise.
std::vector<YAML::Node> load_all_yaml(std::string_view text, const YamlLimits& limits = {});

// The first document of `text` (a null node for an empty text), like
// YAML::Load, once the limits hold for every document.
YAML::Node load_yaml(std::string_view text, const YamlLimits& limits = {});

// The first document of the file at `file`, like YAML::LoadFile: throws
// YAML::BadFile when it cannot be opened, YAML::ParserException when it is
// larger than limits.max_bytes (checked before reading) or breaks a limit.
YAML::Node load_yaml_file(const std::filesystem::path& file, const YamlLimits& limits = {});

}  // namespace mmm

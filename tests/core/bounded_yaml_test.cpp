#include "core/bounded_yaml.h"

#include <gtest/gtest.h>

#include <string>

#include "tests/support/test_data.h"

namespace mmm {
namespace {

// The message of the ParserException that loading `text` raises ("" if none).
std::string yaml_refusal(const std::string& text, const YamlLimits& limits = {}) {
  try {
    (void)load_all_yaml(text, limits);
  } catch (const YAML::ParserException& error) {
    return "line " + std::to_string(error.mark.line + 1) + ": " + error.msg;
  }
  return "";
}

// Ten levels of aliases, each naming the previous one ten times: about 700
// bytes standing for 10^10 nodes.
std::string alias_bomb() {
  std::string text = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int level = 1; level < 10; ++level) {
    const std::string previous = "*a" + std::to_string(level - 1);
    text += "a" + std::to_string(level) + ": &a" + std::to_string(level) + " [";
    for (int i = 0; i < 10; ++i) text += (i ? ", " : "") + previous;
    text += "]\n";
  }
  return text;
}

TEST(BoundedYamlTest, OrdinaryDocumentsLoadAsYamlCppLoadsThem) {
  const std::string text = "name: leg\nitems: [1, 2, {a: b}]\nshared: &s {k: v}\nagain: *s\n";
  const YAML::Node root = load_yaml(text);
  EXPECT_EQ(root["name"].as<std::string>(), "leg");
  EXPECT_EQ(root["items"].size(), 3U);
  EXPECT_EQ(root["again"]["k"].as<std::string>(), "v");
  EXPECT_EQ(load_all_yaml("a: 1\n---\nb: 2\n").size(), 2U);
  EXPECT_TRUE(load_yaml("").IsNull());
}

TEST(BoundedYamlTest, AnAliasInsideItsOwnAnchorIsRefusedAtItsLine) {
  EXPECT_EQ(yaml_refusal("a: &a [*a]\n").substr(0, 7), "line 1:");
  EXPECT_NE(yaml_refusal("a: &a [*a]\n").find("contains it"), std::string::npos);
  EXPECT_NE(yaml_refusal("top:\n  m: &m\n    k: [1, {deep: *m}]\n").find("line 3"),
            std::string::npos);
}

TEST(BoundedYamlTest, AnAliasBombIsRefusedBeforeAnyNodeIsBuilt) {
  const std::string bomb = alias_bomb();
  ASSERT_LT(bomb.size(), 1000U);
  const std::string refusal = yaml_refusal(bomb);
  EXPECT_NE(refusal.find("more than 2000000 nodes"), std::string::npos) << refusal;
  // The same shape two levels shallower (10^3 * 10 nodes) is fine.
  std::string small = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  small += "a1: &a1 [*a0, *a0, *a0, *a0, *a0, *a0, *a0, *a0, *a0, *a0]\n";
  small += "a2: [*a1, *a1, *a1, *a1, *a1, *a1, *a1, *a1, *a1, *a1]\n";
  EXPECT_EQ(yaml_refusal(small), "");
  // Counting is exact: 1 map + 3 keys + (1 + 10) + (1 + 10 * 11) + (1 + 10 * 111).
  EXPECT_EQ(yaml_refusal(small, {.max_nodes = 1 + 3 + 11 + 111 + 1111}), "");
  EXPECT_NE(yaml_refusal(small, {.max_nodes = 1 + 3 + 11 + 111 + 1110}), "");
}

TEST(BoundedYamlTest, NestingIsLimitedWithAliasesExpanded) {
  std::string deep(300, '[');
  deep += std::string(300, ']');
  EXPECT_NE(yaml_refusal(deep).find("nested more than 128"), std::string::npos);
  // Each level alone is shallow; the alias puts the anchored node 3 deep.
  const std::string text = "a: &a [[[1]]]\nb: [[*a]]\n";
  EXPECT_EQ(yaml_refusal(text, {.max_depth = 6}), "");
  EXPECT_NE(yaml_refusal(text, {.max_depth = 5}), "");
}

TEST(BoundedYamlTest, AFileIsCheckedForSizeBeforeItIsRead) {
  const test::ScratchDir dir("bounded_yaml");
  const std::filesystem::path file =
      test::write_file(dir / "big.yaml", "k: " + std::string(200, 'v'));
  EXPECT_EQ(load_yaml_file(file)["k"].as<std::string>().size(), 200U);
  try {
    (void)load_yaml_file(file, {.max_bytes = 100});
    FAIL() << "no error";
  } catch (const YAML::ParserException& error) {
    EXPECT_NE(error.msg.find("203 bytes; at most 100"), std::string::npos) << error.msg;
  }
  EXPECT_THROW((void)load_yaml_file(dir / "missing.yaml"), YAML::BadFile);
  EXPECT_THROW((void)load_yaml_file(dir.path()), YAML::BadFile);
}

}  // namespace
}  // namespace mmm

namespace mmm {
namespace {

TEST(BoundedYamlTest, ANulByteIsRefusedWithItsLineBeforeParsing) {
  const std::string text = std::string("a: 1\nb: >-\n  x") + '\0' + "y\n";
  try {
    (void)load_yaml(text);
    FAIL() << "expected a ParserException";
  } catch (const YAML::ParserException& e) {
    EXPECT_EQ(e.mark.line, 2);
    EXPECT_EQ(e.mark.column, 3);
    EXPECT_NE(std::string(e.what()).find("NUL byte"), std::string::npos) << e.what();
  }
}

// yaml-cpp 0.7 reads a stray ',' as an empty document and starts the next
// one at the same place without end (found by fuzzing a recipe).
TEST(BoundedYamlTest, AStrayCommaThatWouldMakeEmptyDocumentsWithoutEndIsRefusedAtItsLine) {
  const std::string refusal = yaml_refusal("# a recipe\n, name: leg\n");
  EXPECT_EQ(refusal.substr(0, 7), "line 2:") << refusal;
  EXPECT_NE(refusal.find("stray ','"), std::string::npos) << refusal;
  EXPECT_NE(yaml_refusal(","), "");
}

TEST(BoundedYamlTest, TheNodeLimitHoldsForAllDocumentsOfTheText) {
  std::string documents;
  for (int i = 0; i < 10; ++i) documents += "[a, b]\n---\n";
  documents += "[a, b]\n";
  EXPECT_EQ(yaml_refusal(documents, {.max_nodes = 33}), "");
  EXPECT_NE(yaml_refusal(documents, {.max_nodes = 32}).find("more than 32 nodes"),
            std::string::npos);
}

}  // namespace
}  // namespace mmm

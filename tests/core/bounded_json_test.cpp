#include "core/bounded_json.h"

#include <gtest/gtest.h>

#include <string>

namespace mmm {
namespace {

std::string nested(std::size_t levels) {
  return std::string(levels, '[') + std::string(levels, ']');
}

TEST(BoundedJsonTest, OrdinaryTextParsesAsNlohmannParsesIt) {
  const nlohmann::json value = parse_json(R"({"a": [1, 2, {"b": "c"}], "d": null})");
  EXPECT_EQ(value["a"][2]["b"], "c");
  EXPECT_EQ(parse_json(nested(64)).size(), 1U);
  EXPECT_THROW((void)parse_json("{\"a\": }"), nlohmann::json::parse_error);
  EXPECT_TRUE(parse_json_or_discarded("{\"a\": }").is_discarded());
}

TEST(BoundedJsonTest, DeepNestingIsRefusedAtTheByteThatPassesTheLimit) {
  // 100,000 levels (200 KB) used to overflow the stack of whatever touched
  // the parsed value.
  const std::string deep = nested(100000);
  try {
    (void)parse_json(deep);
    FAIL() << "no error";
  } catch (const nlohmann::json::parse_error& error) {
    EXPECT_EQ(error.byte, 65U);
    EXPECT_NE(std::string(error.what()).find("nested more than 64 levels"), std::string::npos);
  }
  EXPECT_TRUE(parse_json_or_discarded(deep).is_discarded());
  EXPECT_THROW((void)parse_json(nested(65)), nlohmann::json::parse_error);
  EXPECT_EQ(parse_json(nested(10), {.max_depth = 10}).size(), 1U);
  EXPECT_THROW((void)parse_json(nested(11), {.max_depth = 10}), nlohmann::json::parse_error);
}

TEST(BoundedJsonTest, BracketsInsideStringsDoNotCount) {
  const std::string text = R"({"s": "[[[[{{{{ \" [[[[", "t": ["\\", "]]]]"]})";
  const nlohmann::json value = parse_json(text, {.max_depth = 2});
  EXPECT_EQ(value["t"][1], "]]]]");
  // Closing brackets inside a string do not lower the count either.
  EXPECT_THROW((void)parse_json(R"([["]]]]", [1]]])", {.max_depth = 2}),
               nlohmann::json::parse_error);
}

TEST(BoundedJsonTest, ALongTextIsRefusedBeforeParsing) {
  const std::string text = "\"" + std::string(100, 'x') + "\"";
  EXPECT_EQ(parse_json(text).get<std::string>().size(), 100U);
  try {
    (void)parse_json(text, {.max_bytes = 50});
    FAIL() << "no error";
  } catch (const nlohmann::json::parse_error& error) {
    EXPECT_NE(std::string(error.what()).find("102 bytes; at most 50"), std::string::npos);
  }
  EXPECT_TRUE(parse_json_or_discarded(text, {.max_bytes = 50}).is_discarded());
}

}  // namespace
}  // namespace mmm

#include "workflow/definition/yaml_schema.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/errors.h"
#include "workflow/definition/workflow_loader.h"

namespace mmm::workflow {
namespace {

using ::testing::HasSubstr;

std::vector<SchemaViolation> check(const std::string& schema, const std::string& document) {
  return YamlSchema::from_text(schema, "test schema").validate(YAML::Load(document));
}

// Messages only, for compact expectations.
std::vector<std::string> messages(const std::string& schema, const std::string& document) {
  std::vector<std::string> out;
  for (const auto& v : check(schema, document)) out.push_back(v.text());
  return out;
}

TEST(YamlSchemaTest, IntegerIsANumberButNotTheOtherWayRound) {
  EXPECT_TRUE(check("type: integer", "3").empty());
  EXPECT_FALSE(check("type: integer", "-0x1F").empty());  // YAML 1.2 hex has no sign: a string
  EXPECT_TRUE(check("type: integer", "0x1F").empty());
  EXPECT_THAT(messages("type: integer", "3.5"),
              ::testing::ElementsAre("top level: expected integer, got number 3.5"));
  EXPECT_TRUE(check("type: number", "3").empty());
  EXPECT_TRUE(check("type: number", "3.5e2").empty());
  EXPECT_TRUE(check("type: number", ".inf").empty());
  EXPECT_THAT(messages("type: number", "'3'"),
              ::testing::ElementsAre("top level: expected number, got string '3'"));
}

TEST(YamlSchemaTest, TypeListsAndYaml12Scalars) {
  const std::string schema = "type: [string, 'null']";
  EXPECT_TRUE(check(schema, "~").empty());
  EXPECT_TRUE(check(schema, "yes").empty());  // a string in YAML 1.2, not a boolean
  EXPECT_THAT(messages(schema, "12"),
              ::testing::ElementsAre("top level: expected string or null, got integer 12"));
  EXPECT_TRUE(check("type: boolean", "True").empty());
  EXPECT_FALSE(check("type: boolean", "on").empty());
  EXPECT_TRUE(check("type: string", "!!str 12").empty());  // explicit tag wins
  EXPECT_TRUE(check("type: object", "{a: 1}").empty());
  EXPECT_TRUE(check("type: array", "[1, 2]").empty());
  EXPECT_FALSE(check("type: array", "{a: 1}").empty());
}

TEST(YamlSchemaTest, RequiredKeyIsReportedAtTheMapping) {
  const auto violations = check("{type: object, required: [name, id]}", "\n  id: 3\n");
  ASSERT_EQ(violations.size(), 1U);
  EXPECT_EQ(violations[0].text(), "top level: missing required key 'name'");
  EXPECT_EQ(violations[0].where.line, 2);
  EXPECT_EQ(violations[0].where.column, 3);
}

TEST(YamlSchemaTest, PropertiesCheckTheirValuesWithAPath) {
  const std::string schema = R"(
type: object
properties:
  size: {type: integer}
  tags: {type: array, items: {type: string}}
)";
  const auto violations = check(schema, "size: big\ntags: [a, 2, c]\n");
  ASSERT_EQ(violations.size(), 2U);
  EXPECT_EQ(violations[0].text(), "size: expected integer, got string 'big'");
  EXPECT_EQ(violations[0].where.line, 1);
  EXPECT_EQ(violations[0].where.column, 7);
  EXPECT_EQ(violations[1].text(), "tags[1]: expected string, got integer 2");
  EXPECT_EQ(violations[1].where.line, 2);
  EXPECT_EQ(violations[1].where.column, 11);
}

TEST(YamlSchemaTest, AdditionalPropertiesFalseNamesTheUnknownKeyAndSuggests) {
  const std::string schema = R"(
type: object
additionalProperties: false
properties: {params: true, inputs: true}
)";
  const auto violations = check(schema, "inputs: {}\nparam: {}\n");
  ASSERT_EQ(violations.size(), 1U);
  EXPECT_EQ(violations[0].where.line, 2);
  EXPECT_EQ(violations[0].where.column, 1);
  EXPECT_EQ(violations[0].message,
            "unknown key 'param'; did you mean 'params'? (allowed: params, inputs)");
}

TEST(YamlSchemaTest, AdditionalPropertiesSchemaChecksTheOtherKeys) {
  const std::string schema =
      "{type: object, properties: {a: true}, additionalProperties: "
      "{type: integer}}";
  EXPECT_TRUE(check(schema, "{a: x, b: 1, c: 2}").empty());
  EXPECT_THAT(messages(schema, "{a: x, b: y}"),
              ::testing::ElementsAre("b: expected integer, got string 'y'"));
}

TEST(YamlSchemaTest, PatternPropertiesApplyToMatchingKeys) {
  const std::string schema = R"(
type: object
patternProperties: {"^x_": {type: integer}}
additionalProperties: false
)";
  EXPECT_TRUE(check(schema, "{x_a: 1, x_b: 2}").empty());
  EXPECT_THAT(messages(schema, "{x_a: one, y: 2}"),
              ::testing::ElementsAre("x_a: expected integer, got string 'one'",
                                     "top level: unknown key 'y' (allowed: (none))"));
}

TEST(YamlSchemaTest, PropertyNamesAreCheckedAsStringsAtTheKey) {
  const std::string schema = "{type: object, propertyNames: {type: string, pattern: '^[a-z]+$'}}";
  EXPECT_TRUE(check(schema, "{abc: 1}").empty());
  const auto violations = check(schema, "abc: 1\nAbc: 2\n123: 3\n");
  ASSERT_EQ(violations.size(), 2U);  // 123 is a string key, but not lower-case letters
  EXPECT_EQ(violations[0].text(), "Abc: 'Abc' does not match the pattern ^[a-z]+$");
  EXPECT_EQ(violations[0].where.line, 2);
  EXPECT_EQ(violations[1].where.line, 3);
}

TEST(YamlSchemaTest, ItemsAndMinItems) {
  const std::string schema = "{type: array, minItems: 2, items: {type: integer}}";
  EXPECT_TRUE(check(schema, "[1, 2]").empty());
  EXPECT_THAT(messages(schema, "[]"),
              ::testing::ElementsAre("top level: expected at least 2 item(s), got 0"));
  const auto violations = check(schema, "- 1\n- x\n");
  ASSERT_EQ(violations.size(), 1U);
  EXPECT_EQ(violations[0].text(), "[1]: expected integer, got string 'x'");
  EXPECT_EQ(violations[0].where.line, 2);
  EXPECT_EQ(violations[0].where.column, 3);
}

TEST(YamlSchemaTest, EnumAndConstCompareLikeJsonSchema) {
  EXPECT_TRUE(check("enum: [a, 1]", "a").empty());
  EXPECT_TRUE(check("enum: [a, 1]", "1.0").empty());  // 1.0 == 1
  EXPECT_THAT(messages("enum: [a, 1]", "'1'"),
              ::testing::ElementsAre("top level: expected one of 'a', 1, got string '1'"));
  EXPECT_TRUE(check("const: true", "true").empty());
  EXPECT_THAT(messages("const: 1", "2"),
              ::testing::ElementsAre("top level: expected 1, got integer 2"));
  EXPECT_FALSE(check("const: 'null'", "~").empty());  // the string "null" is not null
  EXPECT_TRUE(check("const: null", "~").empty());
}

TEST(YamlSchemaTest, PatternSearchesAnywhereUnlessAnchored) {
  EXPECT_TRUE(check("pattern: b", "abc").empty());
  EXPECT_FALSE(check("pattern: ^b", "abc").empty());
  EXPECT_TRUE(check("pattern: ^b", "12").empty());  // pattern applies to strings only
  EXPECT_THAT(messages("pattern: '^[a-z]+\\.[a-z]+$'", "load/mesh"),
              ::testing::ElementsAre("top level: 'load/mesh' does not match the pattern "
                                     "^[a-z]+\\.[a-z]+$"));
}

TEST(YamlSchemaTest, MinimumMaximumAndMinLength) {
  const std::string range = "{type: number, minimum: 0, maximum: 180}";
  EXPECT_TRUE(check(range, "0").empty());
  EXPECT_TRUE(check(range, "180.0").empty());
  EXPECT_THAT(messages(range, "-1"),
              ::testing::ElementsAre("top level: -1 is below the minimum 0"));
  EXPECT_THAT(messages(range, "180.5"),
              ::testing::ElementsAre("top level: 180.5 is above the maximum 180"));
  EXPECT_FALSE(check(range, ".nan").empty());                  // NaN is in no range
  EXPECT_TRUE(check("minLength: 1", "\"\xC3\xA9\"").empty());  // one code point, two bytes
  EXPECT_THAT(messages("minLength: 2", "\"\xC3\xA9\""),
              ::testing::ElementsAre("top level: '\xC3\xA9' is shorter than 2 character(s)"));
}

TEST(YamlSchemaTest, RefResolvesDefsAndTheRoot) {
  const std::string schema = R"(
type: object
properties:
  id: {$ref: "#/$defs/identifier"}
  children: {type: array, items: {$ref: "#"}}
$defs:
  identifier: {type: string, pattern: "^[a-z]+$", description: lower-case letters}
)";
  EXPECT_TRUE(check(schema, "{id: a, children: [{id: b}, {id: c, children: []}]}").empty());
  EXPECT_THAT(messages(schema, "{id: a, children: [{id: B}]}"),
              ::testing::ElementsAre("children[0].id: 'B' does not match the pattern ^[a-z]+$ "
                                     "(lower-case letters)"));
}

TEST(YamlSchemaTest, AnyOfNeedsOneMatchOneOfExactlyOne) {
  const std::string any = "anyOf: [{type: integer}, {type: string, minLength: 3}]";
  EXPECT_TRUE(check(any, "7").empty());
  EXPECT_TRUE(check(any, "abc").empty());
  EXPECT_THAT(messages(any, "ab"),
              ::testing::ElementsAre("top level: matches none of the 2 alternatives: 1) "
                                     "expected integer, got string 'ab'; 2) 'ab' is shorter "
                                     "than 3 character(s)"));
  const std::string one = "oneOf: [{type: number}, {type: integer}]";
  EXPECT_TRUE(check(one, "2.5").empty());
  EXPECT_THAT(
      messages(one, "2"),
      ::testing::ElementsAre("top level: matches 2 of the 2 alternatives, expected exactly one"));
}

TEST(YamlSchemaTest, BooleanSchemas) {
  EXPECT_TRUE(check("true", "{anything: [1, 2]}").empty());
  EXPECT_THAT(messages("{properties: {x: false}}", "{x: 1}"),
              ::testing::ElementsAre("x: no value is allowed here"));
}

TEST(YamlSchemaTest, EmptyValueIsReportedAtItsKey) {
  const auto violations = check("{properties: {params: {type: object}}}", "params:\nnext: 1\n");
  ASSERT_EQ(violations.size(), 1U);
  EXPECT_EQ(violations[0].text(), "params: expected object, got null");
  EXPECT_EQ(violations[0].where.line, 1);  // yaml-cpp marks the empty value at the next line
  EXPECT_EQ(violations[0].where.column, 1);
}

TEST(YamlSchemaTest, CollectsEveryViolation) {
  const std::string schema = R"(
type: object
required: [a]
additionalProperties: false
properties:
  b: {type: integer}
  c: {type: array, minItems: 1}
)";
  EXPECT_EQ(check(schema, "{b: x, c: [], d: 1}").size(), 4U);
}

TEST(YamlSchemaTest, BadSchemasAreRejectedWhenLoaded) {
  EXPECT_THAT([] { YamlSchema::from_text("propertys: {}", "s.yaml"); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr(
                  "s.yaml: schema #/propertys: unsupported keyword 'propertys'; did you mean "
                  "'properties'?")));
  EXPECT_THAT([] { YamlSchema::from_text("$ref: '#/$defs/nope'", "s.yaml"); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("does not resolve")));
  EXPECT_THAT([] { YamlSchema::from_text("pattern: '[a-'", "s.yaml"); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("not a valid ECMAScript")));
  EXPECT_THAT([] { YamlSchema::from_text("type: text", "s.yaml"); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("unknown type 'text'")));
  EXPECT_THAT([] { YamlSchema::from_text("items: {$defs: {a: true}}", "s.yaml"); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("top level only")));
  EXPECT_THAT([] { YamlSchema::from_text("enum: [[1]]", "s.yaml"); },
              ::testing::ThrowsMessage<InvalidInputError>(HasSubstr("only scalar values")));
  EXPECT_THROW(YamlSchema::from_file("/nonexistent/schema.yaml"), IoError);
}

TEST(YamlSchemaTest, TheWorkflowSchemaCompiles) {
  EXPECT_NO_THROW(YamlSchema::from_file(find_workflow_schema()));
}

}  // namespace
}  // namespace mmm::workflow

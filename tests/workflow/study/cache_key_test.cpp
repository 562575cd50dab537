#include "workflow/study/cache_key.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"

namespace mmm::workflow {
namespace {

using ::testing::ElementsAre;

NodeSpec spec() {
  return NodeSpec{"decimate_mesh", 1, "Lower-resolution copy"}
      .input<port::Mesh>("mesh", "Surface")
      .param<double>("weight", 1.0, "A weight", {.min = 0})
      .param<std::int64_t>("faces", 5000, "Faces", {.min = 4})
      .output<port::Mesh>("decimated", "Result");
}

CacheKeyParts parts(const std::map<std::string, ParamValue>& given, std::string input_hash) {
  return {"decimate_mesh", 1, effective_params(spec(), given), {{"mesh", std::move(input_hash)}}};
}

TEST(CacheKeyTest, DefaultsAndNumberSpellingsGiveOneKey) {
  const std::string hash(64, 'a');
  const std::string implicit = cache_key(parts({}, hash));
  const std::string spelled =
      cache_key(parts({{"weight", 1.0}, {"faces", std::int64_t{5000}}}, hash));
  const std::string integer_weight = cache_key(parts({{"weight", std::int64_t{1}}}, hash));
  EXPECT_EQ(implicit, spelled);
  EXPECT_EQ(implicit, integer_weight);
  EXPECT_EQ(implicit.size(), 64U);
}

TEST(CacheKeyTest, EveryIngredientChangesTheKey) {
  const std::string hash(64, 'a');
  const CacheKeyParts base = parts({}, hash);
  CacheKeyParts version = base;
  version.version = 2;
  EXPECT_NE(cache_key(base), cache_key(version));
  EXPECT_NE(cache_key(base), cache_key(parts({{"faces", std::int64_t{4000}}}, hash)));
  EXPECT_NE(cache_key(base), cache_key(parts({}, std::string(64, 'b'))));
}

TEST(CacheKeyTest, DescribesWhatChanged) {
  const CacheKeyParts before = parts({}, std::string(64, 'a'));
  const CacheKeyParts after = parts({{"faces", std::int64_t{2000}}}, std::string(64, 'b'));
  EXPECT_THAT(describe_key_changes(before, after),
              ElementsAre("parameter 'faces' changed from 5000 to 2000",
                          "input 'mesh' changed content (aaaaaaaaaaaa -> bbbbbbbbbbbb)"));
  EXPECT_TRUE(describe_key_changes(before, before).empty());
}

TEST(CacheKeyTest, JsonRoundTrip) {
  const CacheKeyParts original = parts({{"weight", 0.25}}, std::string(64, 'c'));
  const CacheKeyParts back = cache_key_parts_from_json(cache_key_json(original));
  EXPECT_EQ(cache_key(back), cache_key(original));
}

TEST(CacheKeyTest, RejectsUnknownAndInvalidParameters) {
  EXPECT_THROW(effective_params(spec(), {{"nope", 1.0}}), InvalidInputError);
  EXPECT_THROW(effective_params(spec(), {{"faces", std::int64_t{2}}}), InvalidInputError);
}

}  // namespace
}  // namespace mmm::workflow

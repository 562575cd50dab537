#include "worklists/operators.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "worklists/task_actions.h"

namespace mmm::worklists {
namespace {

using ::testing::HasSubstr;

TEST(OperatorsTest, TokensIdentifyTheirOperatorAndOnlyTheirHashIsStored) {
  const test::ScratchDir root("operators");
  const std::string ana = add_operator(root.path(), "ana");
  const std::string sue = add_operator(root.path(), "sue", false, kSupervisorRole);
  EXPECT_EQ(ana.size(), 64U);
  EXPECT_EQ(operator_for_token(root.path(), ana), "ana");
  EXPECT_EQ(operator_for_token(root.path(), sue), "sue");
  EXPECT_EQ(operator_for_token(root.path(), std::string(64, '0')), std::nullopt);
  const std::string file = test::read_text(operators_file(root.path()));
  EXPECT_EQ(file.find(ana), std::string::npos);
  EXPECT_FALSE(is_supervisor(root.path(), "ana"));
  EXPECT_TRUE(is_supervisor(root.path(), "sue"));
  EXPECT_FALSE(is_supervisor(root.path(), "nobody-here"));
  EXPECT_THROW(add_operator(root.path(), "ana"), InvalidInputError) << "exists";
  EXPECT_THROW(check_registered_operator(root.path(), "ben"), InvalidInputError);
}

TEST(OperatorsTest, ReservedNamesAndUnknownRolesAreRefused) {
  const test::ScratchDir root("operators-reserved");
  for (const char* name : {"mmm", "MMM", "system", "Root", "admin", "administrator"}) {
    try {
      (void)add_operator(root.path(), name);
      FAIL() << name << " was registered";
    } catch (const TaskError& error) {
      EXPECT_THAT(error.what(), HasSubstr("is reserved")) << name;
    }
  }
  EXPECT_THROW(add_operator(root.path(), "ana", false, "owner"), InvalidInputError);
  // A role edited into the file by hand that mmm does not know.
  std::filesystem::create_directories(operators_file(root.path()).parent_path());
  test::write_file(operators_file(root.path()),
                   R"({"format": "mmm-operators", "version": 1, "operators": [)"
                   R"({"name": "eve", "token_sha256": "00", "role": "god"}]})");
  try {
    (void)read_operators(root.path());
    FAIL() << "an unknown role was read";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("role 'god'"));
  }
}

}  // namespace
}  // namespace mmm::worklists

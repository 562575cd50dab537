#pragma once
// Registers a test operator under a root with `mmm operator add` and keeps
// the token it prints in a file, for the command line's --token-file.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/support/test_data.h"

namespace mmm::test {

// " --token-file FILE" for NAME, registered under root; the file is written
// into `folder`.
inline std::string operator_token_option(const std::filesystem::path& root, const std::string& name,
                                         const std::filesystem::path& folder) {
  const CommandResult added = run_mmm("operator add " + name + " --root " + root.string());
  EXPECT_EQ(added.exit_code, 0) << added.err;
  const std::filesystem::path file = write_file(folder / (name + ".token"), added.out);
  return " --token-file " + file.string();
}

}  // namespace mmm::test

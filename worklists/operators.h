#pragma once
// The operators of a root folder and their access tokens, for the web UI
// (`mmm operator add NAME`, `mmm serve`). Kept in ROOT/.mmm/operators.json:
//   {"format": "mmm-operators", "version": 1,
//    "operators": [{"name": "ana", "token_sha256": "...", "created_at": "...",
//                   "role": "operator"}]}
// Only the SHA-256 of each token is stored: the file gives nobody access.
// Tokens are 32 random bytes as 64 hex characters, shown once at creation.
// Roles: "operator" (the default) works on tasks; "supervisor" may also
// release, reassign or cancel a task someone else has claimed.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace mmm::worklists {

inline constexpr const char* kOperatorRole = "operator";
inline constexpr const char* kSupervisorRole = "supervisor";

struct OperatorRecord {
  std::string name;
  std::string token_sha256;
  std::string created_at;
  std::string role = kOperatorRole;
};

std::filesystem::path operators_file(const std::filesystem::path& root);

// Every registered operator; empty when the file does not exist. Throws
// IoError naming the file when it is damaged.
std::vector<OperatorRecord> read_operators(const std::filesystem::path& root);

// Registers `name` (check_operator_name rules) and returns its new token.
// With `replace`, an existing operator gets a new token (the old one stops
// working); without it an existing name is an InvalidInputError.
std::string add_operator(const std::filesystem::path& root, const std::string& name,
                         bool replace = false, const std::string& role = kOperatorRole);

// Whether `name` is registered under root with the supervisor role.
bool is_supervisor(const std::filesystem::path& root, const std::string& name);

// The operator whose token this is, or nullopt. Constant-time comparison of
// the hashes.
std::optional<std::string> operator_for_token(const std::filesystem::path& root,
                                              const std::string& token);

// Throws InvalidInputError unless `name` is registered under root — when the
// root has an operators file at all (a root without one accepts any valid
// name on the command line, for single-user set-ups).
void check_registered_operator(const std::filesystem::path& root, const std::string& name);

}  // namespace mmm::worklists

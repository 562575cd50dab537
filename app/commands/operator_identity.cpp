#include "app/commands/operator_identity.h"

#include <unistd.h>

#include <cstdlib>
#include <optional>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "worklists/operators.h"

namespace mmm::app {
namespace {

namespace fs = std::filesystem;

// A token file holds the token and perhaps a newline; anything longer than
// this is not a token file.
constexpr std::uintmax_t kMaxTokenFileBytes = 4096;

std::string trimmed(std::string text) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!text.empty() && blank(text.back())) text.pop_back();
  std::size_t start = 0;
  while (start < text.size() && blank(text[start])) ++start;
  return text.substr(start);
}

std::string token_from_file(const fs::path& file) {
  std::error_code error;
  const std::uintmax_t size = fs::file_size(file, error);
  if (error) throw IoError(file, "cannot read the operator token file: " + error.message());
  if (size > kMaxTokenFileBytes) {
    throw IoError(file, "is " + std::to_string(size) +
                            " bytes: not an operator token file (it holds the one line "
                            "'mmm operator add' printed)");
  }
  return trimmed(read_file_bytes(file, size));
}

std::string env(const char* name) {
  const char* value = std::getenv(name);
  return value == nullptr ? std::string() : std::string(value);
}

// The token given: --token-file, else $MMM_OPERATOR_TOKEN, else the file
// named by $MMM_OPERATOR_TOKEN_FILE; empty when none.
std::string given_token(const OperatorCredentials& credentials) {
  if (!credentials.token_file.empty()) return token_from_file(credentials.token_file);
  if (std::string token = trimmed(env("MMM_OPERATOR_TOKEN")); !token.empty()) return token;
  if (const std::string file = env("MMM_OPERATOR_TOKEN_FILE"); !file.empty()) {
    return token_from_file(file);
  }
  return {};
}

}  // namespace

worklists::Actor command_line_actor(const fs::path& root, const OperatorCredentials& credentials) {
  const fs::path operators = worklists::operators_file(root);
  std::error_code error;
  if (!fs::exists(operators, error)) {
    throw InvalidInputError(
        "no operators are registered under " + root.string() +
        ", so no one can be authenticated; hint: 'mmm operator add NAME --root " + root.string() +
        "' prints NAME's token, then export MMM_OPERATOR_TOKEN=TOKEN (or keep it in a file and "
        "give --token-file FILE)");
  }
  if (!credentials.override_reason.empty()) {
    if (credentials.operator_name.empty()) {
      throw InvalidInputError("--admin-override needs --operator NAME: the operator acted for");
    }
    if (trimmed(credentials.override_reason).empty()) {
      throw InvalidInputError(
          "--admin-override needs a reason (it is recorded in the audit trail); blanks are not "
          "a reason");
    }
    if (::access(operators.c_str(), W_OK) != 0) {
      throw InvalidInputError(
          "an administrative override is for whoever may change " + operators.string() +
          " (who can register operators, hence act as any of them); this account may not. "
          "hint: use the operator's own token (MMM_OPERATOR_TOKEN or --token-file)");
    }
    worklists::check_registered_operator(root, credentials.operator_name);
    worklists::Actor actor{credentials.operator_name, MMM_VERSION,
                           worklists::is_supervisor(root, credentials.operator_name)};
    actor.override_reason = trimmed(credentials.override_reason);
    return actor;
  }
  const std::string token = given_token(credentials);
  if (token.empty()) {
    throw InvalidInputError(
        "no operator token: operator actions on the command line are authenticated like the web "
        "UI; hint: export MMM_OPERATOR_TOKEN=TOKEN, or give --token-file FILE (the token 'mmm "
        "operator add NAME' printed; never on the command line), or, for scripts run by the "
        "root's administrator, --operator NAME --admin-override REASON (audited)");
  }
  const std::optional<std::string> name = worklists::operator_for_token(root, token);
  if (!name) {
    throw InvalidInputError("unknown operator token for " + root.string() +
                            "; hint: 'mmm operator add NAME --root " + root.string() +
                            " --replace' gives NAME a new one");
  }
  if (!credentials.operator_name.empty() && credentials.operator_name != *name) {
    throw InvalidInputError("the token is operator '" + *name + "''s, not '" +
                            credentials.operator_name +
                            "''s: an operator acts only under their own token");
  }
  return {*name, MMM_VERSION, worklists::is_supervisor(root, *name)};
}

}  // namespace mmm::app

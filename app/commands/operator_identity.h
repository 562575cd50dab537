#pragma once
// Who acts in `mmm task ...` on the command line: the operator whose token is
// given (never as an argument: $MMM_OPERATOR_TOKEN, or a file named by
// --token-file or $MMM_OPERATOR_TOKEN_FILE), as in the web UI; or, for
// scripts run by whoever administers the root, a named operator by an
// administrative override, which the audit trail records with its reason.

#include <filesystem>
#include <string>

#include "worklists/task_actions.h"

namespace mmm::app {

struct OperatorCredentials {
  std::string operator_name;    // --operator: must match the token's, if both given
  std::string token_file;       // --token-file
  std::string override_reason;  // --admin-override: act as operator_name without a token
};

// The actor of a command-line action under root. Throws InvalidInputError
// naming the rule broken: no operators registered under the root, no token,
// an unknown token, a token of another operator than --operator, an override
// without --operator or with a blank reason, or an override by someone who
// cannot change the root's operators file (who can may register operators,
// hence act as any of them anyway).
worklists::Actor command_line_actor(const std::filesystem::path& root,
                                    const OperatorCredentials& credentials);

}  // namespace mmm::app

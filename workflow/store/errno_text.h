#pragma once
// The message of an errno value, for the errors of workflow/store/
// (artifact_store.cpp, study_lock.cpp). Not part of the public contract.

#include <string>
#include <system_error>

namespace mmm::workflow::detail {

// "No such file or directory" for ENOENT, and so on.
inline std::string errno_text(int code) {
  return std::error_code(code, std::generic_category()).message();
}

}  // namespace mmm::workflow::detail

#pragma once
// Where a problem in a workflow file is, and what it is: the
// `file:line:col: message` lines that `mmm validate` prints.

#include <string>

namespace mmm::workflow {

// A position in a YAML file, 1-based; line 0 means "unknown" (e.g. the file
// does not exist).
struct SourceLocation {
  int line = 0;
  int column = 0;

  [[nodiscard]] bool known() const { return line > 0; }
  // "12:5", or "?" when unknown.
  [[nodiscard]] std::string text() const;
};

struct Diagnostic {
  std::string file;  // the path as the user gave it
  int line = 0;      // 1-based; 0 when the problem has no position
  int column = 0;    // 1-based
  std::string message;

  // "file:line:col: message", or "file: message" without a position.
  [[nodiscard]] std::string text() const;
};

}  // namespace mmm::workflow

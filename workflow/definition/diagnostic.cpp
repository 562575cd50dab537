#include "workflow/definition/diagnostic.h"

namespace mmm::workflow {

std::string SourceLocation::text() const {
  if (!known()) return "?";
  return std::to_string(line) + ":" + std::to_string(column);
}

std::string Diagnostic::text() const {
  if (line <= 0) return file + ": " + message;
  return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message;
}

}  // namespace mmm::workflow

#include "app/report/json_file.h"

#include <fstream>
#include <sstream>

#include "core/bounded_json.h"
#include "core/errors.h"

namespace mmm::app::report {

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InvalidInputError(file.string() + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::optional<nlohmann::json> read_json_if_present(const std::filesystem::path& file,
                                                   const std::string& hint) {
  if (!std::filesystem::exists(file)) return std::nullopt;
  try {
    return parse_json(read_text(file));
  } catch (const nlohmann::json::parse_error& error) {
    throw InvalidInputError(file.string() + ": not JSON (" + error.what() + "); " + hint);
  }
}

}  // namespace mmm::app::report

#pragma once
// Reading the study's output files for the report.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace mmm::app::report {

// Whole file. Throws InvalidInputError naming a file that cannot be read.
std::string read_text(const std::filesystem::path& file);

// The parsed file, or nullopt when it does not exist. Throws
// InvalidInputError naming a file that cannot be read or is not JSON (with
// `hint` on what to do).
std::optional<nlohmann::json> read_json_if_present(
    const std::filesystem::path& file, const std::string& hint = "re-run the node that wrote it");

}  // namespace mmm::app::report

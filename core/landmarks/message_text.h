#pragma once
// Text pieces of the error messages of core/landmarks/ (landmark_set.cpp,
// landmark_validation.cpp, slicer_markups.cpp). Not part of the public
// contract.

#include <initializer_list>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>

namespace mmm::landmarks::detail {

// The parts one after the other (one allocation, for messages built in loops).
inline std::string concat(std::initializer_list<std::string_view> parts) {
  std::string out;
  for (const std::string_view part : parts) out += part;
  return out;
}

// A short rendering of a JSON value for messages (long values cut).
std::string describe_json(const nlohmann::json& value);

}  // namespace mmm::landmarks::detail

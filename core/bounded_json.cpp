#include "core/bounded_json.h"

#include <optional>
#include <string>

namespace mmm {
namespace {

using Json = nlohmann::json;

// The 1-based byte at which the nesting of arrays and objects first passes
// `max_depth`, if it does. Brackets inside strings do not count.
std::optional<std::size_t> first_byte_too_deep(std::string_view text, std::size_t max_depth) {
  std::size_t depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i + 1;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::nullopt;
}

// The reason `text` is refused before parsing, if it is.
std::optional<Json::parse_error> refusal(std::string_view text, const JsonLimits& limits) {
  if (text.size() > limits.max_bytes) {
    return Json::parse_error::create(101, 0,
                                     "the text is " + std::to_string(text.size()) +
                                         " bytes; at most " + std::to_string(limits.max_bytes) +
                                         " are read",
                                     nullptr);
  }
  if (const auto byte = first_byte_too_deep(text, limits.max_depth)) {
    return Json::parse_error::create(
        101, *byte,
        "arrays and objects nested more than " + std::to_string(limits.max_depth) + " levels deep",
        nullptr);
  }
  return std::nullopt;
}

}  // namespace

Json parse_json(std::string_view text, const JsonLimits& limits) {
  if (auto error = refusal(text, limits)) throw *error;
  return Json::parse(text);
}

Json parse_json_or_discarded(std::string_view text, const JsonLimits& limits) {
  if (refusal(text, limits)) {
    Json discarded(Json::value_t::discarded);
    return discarded;
  }
  return Json::parse(text, nullptr, false);
}

}  // namespace mmm

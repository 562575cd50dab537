#pragma once
// JSON parsing with limits checked before any value is built, for every JSON
// text mmm reads from a file, an operator or a request (landmark sets,
// markups, submissions, view sidecars, reports, indexes).
//
// nlohmann's parser itself is iterative, but copying, printing or walking a
// value recurses once per nesting level: `[[[[...]]]]` 100,000 levels deep
// (200 KB) overflows the stack of whatever touches it afterwards. Nothing
// mmm reads nests more than a few levels, so the text's nesting is measured
// first, in one pass without recursion, and a text deeper than the limit is
// refused with the same exception a syntax error raises.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string_view>

namespace mmm {

struct JsonLimits {
  std::size_t max_bytes = std::size_t{64} << 20;
  std::size_t max_depth = 64;
};

// Like nlohmann::json::parse(text): throws nlohmann::json::parse_error for a
// text that is not JSON, is longer than limits.max_bytes or nests arrays and
// objects deeper than limits.max_depth (the message says which and where).
nlohmann::json parse_json(std::string_view text, const JsonLimits& limits = {});

// Like nlohmann::json::parse(text, nullptr, false): a discarded value (check
// is_discarded()) instead of an exception, for every case parse_json throws.
nlohmann::json parse_json_or_discarded(std::string_view text, const JsonLimits& limits = {});

}  // namespace mmm

#pragma once
// Hints for misspelt names: "did you mean 'params'?" and lists of the names
// that are allowed. Shared by core readers (atlas manifests) and the
// workflow loader.

#include <string>
#include <string_view>
#include <vector>

namespace mmm {

// Levenshtein distance (insertions, deletions, substitutions).
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidates within edit distance 2 of `name`, closest first (ties in
// candidate order).
std::vector<std::string> closest_names(std::string_view name,
                                       const std::vector<std::string>& candidates);

// "a, b, c"; "(none)" for an empty list.
std::string join_names(const std::vector<std::string>& names);

// "; did you mean 'x'?" when a candidate is close, else "".
std::string did_you_mean(std::string_view name, const std::vector<std::string>& candidates);

}  // namespace mmm

#pragma once
// Comma-separated name lists in node parameters ("glut_max1_r, iliacus_r").

#include <string>
#include <vector>

namespace mmm::nodes {

// The names in `text`, split at commas, blanks around each trimmed, empty
// entries dropped, order kept.
std::vector<std::string> split_names(const std::string& text);

}  // namespace mmm::nodes

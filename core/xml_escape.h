#pragma once
// Text for XML and HTML (attribute values and element content).

#include <string>
#include <string_view>

namespace mmm {

// `text` appended to `out` with the five XML specials escaped (& < > " ').
// Control characters other than tab, newline and return are not allowed in
// XML 1.0 at all (not even as references): they become spaces.
void append_xml_escaped(std::string& out, std::string_view text);

// The same, as a new string.
std::string xml_escaped(std::string_view text);

}  // namespace mmm

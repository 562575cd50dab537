#pragma once
// Numbers as text in the CSV files and messages of the nodes.

#include <cstdio>
#include <string>
#include <vector>

namespace mmm::nodes {

// `value` with exactly `decimals` digits after the point ("%.*f").
inline std::string fixed(double value, int decimals) {
  std::vector<char> buffer(64);
  std::snprintf(buffer.data(), buffer.size(), "%.*f", decimals, value);
  return buffer.data();
}

}  // namespace mmm::nodes

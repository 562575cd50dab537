#pragma once
// The shortest text of a double, for the messages of core/plot/
// (nice_ticks.cpp, svg_plot.cpp). Not part of the public contract.

#include <array>
#include <charconv>
#include <string>
#include <system_error>

namespace mmm::plot::detail {

// Any double in the shortest form that reads back exactly, for messages.
inline std::string shortest(double value) {
  std::array<char, 32> buffer{};
  const auto [end, error] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  if (error != std::errc{}) return "?";
  return {buffer.data(), end};
}

}  // namespace mmm::plot::detail

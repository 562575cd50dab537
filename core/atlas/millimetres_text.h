#pragma once
// A length as the atlas build and check write it in their messages: two
// decimals and the unit ("3.50 mm").

#include <sstream>
#include <string>

namespace mmm::atlas {

inline std::string millimetres_text(double value) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(2);
  text << value << " mm";
  return text.str();
}

}  // namespace mmm::atlas

#include "app/report/html.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/xml_escape.h"

namespace mmm::app::report {

std::string html_table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows) {
  std::string out = "<table>\n<tr>";
  for (const std::string& cell : header) {
    out += "<th>" + xml_escaped(cell) + "</th>";
  }
  out += "</tr>\n";
  for (const std::vector<std::string>& row : rows) {
    out += "<tr>";
    for (const std::string& cell : row) {
      out += "<td>" + xml_escaped(cell) + "</td>";
    }
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

std::string fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s << std::fixed << std::setprecision(decimals) << value;
  return s.str();
}

}  // namespace mmm::app::report

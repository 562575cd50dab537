#include "app/report/html.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string_view>

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

std::string html_page(const std::string& title, const std::string& body) {
  constexpr std::string_view kStyle =
      "body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}"
      "table{border-collapse:collapse;margin:.5em 0 1em}td,th{border:1px solid #ccc;padding:2px "
      "8px;"
      "font-size:90%;text-align:left}th{background:#f0f0f0}figure{margin:1em 0}"
      "figure img,figure svg{max-width:100%;height:auto}figure "
      "img{max-height:90vh}figcaption{color:#555;font-size:90%}"
      ".pending{color:#a60}";
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
         xml_escaped(title) + "</title>\n<style>" + std::string(kStyle) +
         "</style>\n</head>\n<body>\n<h1>" + xml_escaped(title) + "</h1>\n" + body +
         "</body>\n</html>\n";
}

}  // namespace mmm::app::report

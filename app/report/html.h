#pragma once
// Small pieces of an offline HTML page: escaped text and plain tables. No
// scripts, no external resources.

#include <string>
#include <vector>

namespace mmm::app::report {

// <table> with a header row; every cell is escaped text (core/xml_escape.h).
std::string html_table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows);

// A whole page: the document head with the reports' shared style sheet, the
// title as its <h1>, then `body` (HTML as it is).
std::string html_page(const std::string& title, const std::string& body);

// A number with `decimals` digits after the point ("-" for NaN or infinity).
std::string fixed(double value, int decimals);

}  // namespace mmm::app::report

#pragma once
// Small pieces of an offline HTML page: escaped text and plain tables. No
// scripts, no external resources.

#include <string>
#include <string_view>
#include <vector>

namespace mmm::app::report {

// <table> with a header row; every cell is escaped text (core/xml_escape.h).
std::string html_table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows);

// The pages' shared style sheet (a <style> element's content).
std::string_view report_style();

// A number with `decimals` digits after the point ("-" for NaN or infinity).
std::string fixed(double value, int decimals);

}  // namespace mmm::app::report

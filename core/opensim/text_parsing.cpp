#include "core/opensim/text_parsing.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>
#include <utility>

#include "core/errors.h"

namespace mmm::opensim {

std::vector<TextLine> split_text_lines(std::string_view text) {
  constexpr std::string_view kBom = "\xEF\xBB\xBF";
  if (text.substr(0, kBom.size()) == kBom) text.remove_prefix(kBom.size());
  std::vector<TextLine> lines;
  std::size_t start = 0;
  int number = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c != '\n' && c != '\r') continue;
    lines.push_back({text.substr(start, i - start), number++});
    if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
    start = i + 1;
  }
  if (start < text.size()) lines.push_back({text.substr(start), number});
  return lines;
}

bool is_line_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

std::string_view trim_line_blanks(std::string_view text) {
  while (!text.empty() && is_line_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_line_blank(text.back())) text.remove_suffix(1);
  return text;
}

bool is_xml_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

std::string_view trim_xml_space(std::string_view text) {
  while (!text.empty() && is_xml_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_xml_space(text.back())) text.remove_suffix(1);
  return text;
}

std::vector<std::string_view> split_xml_words(std::string_view text) {
  std::vector<std::string_view> words;
  std::size_t pos = 0;
  while (pos < text.size()) {
    while (pos < text.size() && is_xml_space(text[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < text.size() && !is_xml_space(text[pos])) ++pos;
    if (pos > start) words.push_back(text.substr(start, pos - start));
  }
  return words;
}

namespace {

template <typename Number>
bool parse_whole_token(std::string_view token, Number& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, error] = std::from_chars(token.data(), end, value);
  return error == std::errc() && ptr == end;
}

}  // namespace

bool parse_double_token(std::string_view token, double& value) {
  return parse_whole_token(token, value);
}

bool parse_int_token(std::string_view token, int& value) { return parse_whole_token(token, value); }

std::string quote_for_message(std::string_view text) {
  constexpr std::size_t kMaxShown = 40;
  if (text.size() > kMaxShown) return "'" + std::string(text.substr(0, kMaxShown)) + "...'";
  return "'" + std::string(text) + "'";
}

std::string ascii_lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](char c) {
    return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
  });
  return out;
}

std::string shortest_double_text(double value) {
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return {buffer.data(), result.ptr};
}

void append_number_text(std::string& out, double value, int decimals) {
  if (std::isnan(value)) {
    out += "NaN";
    return;
  }
  // Fixed notation of the largest double needs 309 digits before the point.
  std::array<char, 400> buffer{};
  char* const first = buffer.data();
  char* const last = buffer.data() + buffer.size();
  const std::to_chars_result result =
      decimals < 0 ? std::to_chars(first, last, value)
                   : std::to_chars(first, last, value, std::chars_format::fixed, decimals);
  out.append(first, result.ptr);
}

std::string read_whole_text_file(const std::filesystem::path& file, std::string_view expected) {
  std::error_code error;
  if (!std::filesystem::exists(file, error)) {
    throw IoError(file, "no such file; check the path (relative paths are taken from " +
                            std::filesystem::current_path(error).string() + ")");
  }
  if (std::filesystem::is_directory(file, error)) {
    throw IoError(file, "is a folder, expected " + std::string(expected));
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file, "cannot be opened for reading (permissions?)");
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw IoError(file, "read failed part-way (I/O error)");
  return std::move(content).str();
}

}  // namespace mmm::opensim

#pragma once

// Text helpers shared by the OpenSim readers and writers (.mot/.sto, .trc,
// .osim and marker-set XML): lines, blanks, strict number parsing, quoting
// for error messages and whole-file reads with a clear error.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::opensim {

// One line of a text file without its line end; `number` is 1-based.
struct TextLine {
  std::string_view text;
  int number = 0;
};

// Lines of `text`, split at LF, CRLF or a lone CR, without the line ends. A
// leading UTF-8 byte order mark is dropped.
std::vector<TextLine> split_text_lines(std::string_view text);

// Blanks inside one line of a table: space, tab, vertical tab, form feed.
bool is_line_blank(char c);
std::string_view trim_line_blanks(std::string_view text);

// White space of XML text: space, tab, CR, LF.
bool is_xml_space(char c);
std::string_view trim_xml_space(std::string_view text);
// Tokens separated by runs of XML white space.
std::vector<std::string_view> split_xml_words(std::string_view text);

// The whole token as a number (an optional leading '+' accepted); false for
// an empty token, trailing characters or a value out of range.
bool parse_double_token(std::string_view token, double& value);
bool parse_int_token(std::string_view token, int& value);

// 'text' in single quotes, cut to 40 characters with "..." (for messages).
std::string quote_for_message(std::string_view text);
// ASCII lower case (keys of headers and units are ASCII).
std::string ascii_lower(std::string_view text);
// The shortest text that reads back as the same double.
std::string shortest_double_text(double value);
// Appends `value` with `decimals` fixed decimals, or the shortest exact text
// when `decimals` is negative; NaN is written "NaN".
void append_number_text(std::string& out, double value, int decimals);

// The whole file, or IoError naming it: missing (with the folder relative
// paths are taken from), a folder ("expected <expected>"), unreadable.
std::string read_whole_text_file(const std::filesystem::path& file, std::string_view expected);

}  // namespace mmm::opensim

#include "core/opensim/mot.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/opensim/text_parsing.h"

namespace mmm::opensim {

namespace {

constexpr std::size_t kMaxListed = 12;
constexpr int kMaxMotDecimals = 20;

// Tokens separated by runs of tabs and spaces.
void split_line_words(std::string_view line, std::vector<std::string_view>& words) {
  words.clear();
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && is_line_blank(line[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < line.size() && !is_line_blank(line[pos])) ++pos;
    if (pos > start) words.push_back(line.substr(start, pos - start));
  }
}

enum class HeaderKey { kName, kVersion, kRows, kColumns, kInDegrees, kDataType, kOther };

HeaderKey classify(std::string_view key) {
  const std::string k = ascii_lower(key);
  if (k == "name") return HeaderKey::kName;
  if (k == "version") return HeaderKey::kVersion;
  if (k == "nrows" || k == "datarows" || k == "nr") return HeaderKey::kRows;
  if (k == "ncolumns" || k == "datacolumns" || k == "nc") return HeaderKey::kColumns;
  if (k == "indegrees") return HeaderKey::kInDegrees;
  if (k == "datatype") return HeaderKey::kDataType;
  return HeaderKey::kOther;
}

// A count announced by the header, to check against the data.
struct Announced {
  std::string key;  // as written ("nRows", "datarows")
  int value = 0;
  int line = 0;
};

class MotParser {
 public:
  MotParser(std::string_view text, std::filesystem::path name, const StorageReadOptions& options)
      : name_(std::move(name)), options_(options), lines_(split_text_lines(text)) {}

  StorageTable parse() {
    out_.source = name_;
    const std::size_t labels_index = parse_header();
    const std::size_t first_row = parse_labels(labels_index);
    parse_rows(first_row);
    finish();
    return std::move(out_);
  }

 private:
  [[noreturn]] void fail(int line, const std::string& problem) const {
    throw IoError(name_, "line " + std::to_string(line) + ": " + problem);
  }
  [[noreturn]] void fail(int line, std::string_view column, const std::string& problem) const {
    throw IoError(name_, "line " + std::to_string(line) + ", column " + quote_for_message(column) +
                             ": " + problem);
  }

  // Returns the index of the first line after "endheader".
  std::size_t parse_header() {
    std::size_t end = lines_.size();
    for (std::size_t i = 0; i < lines_.size(); ++i) {
      if (ascii_lower(trim_line_blanks(lines_[i].text)) == "endheader") {
        end = i;
        break;
      }
    }
    if (end == lines_.size()) {
      std::string hint =
          "; expected an OpenSim storage header (name, version=1, nRows=..., "
          "nColumns=..., inDegrees=yes|no) ending in a line 'endheader'";
      if (!lines_.empty() && trim_line_blanks(lines_[0].text).substr(0, 12) == "PathFileType") {
        hint += "; this looks like a .trc marker file: read it with read_trc";
      }
      throw IoError(
          name_, "no 'endheader' line found in " + std::to_string(lines_.size()) + " lines" + hint);
    }
    for (std::size_t i = 0; i < end; ++i) parse_header_line(lines_[i], i == 0);
    return end + 1;
  }

  void parse_header_line(const TextLine& line, bool first) {
    const std::string_view text = trim_line_blanks(line.text);
    if (text.empty() || text.front() == '#') {
      if (ascii_lower(text).find("simm") != std::string::npos) simm_header_ = true;
      return;
    }
    std::string_view key;
    std::string_view value;
    const std::size_t equals = text.find('=');
    if (equals != std::string_view::npos) {
      key = trim_line_blanks(text.substr(0, equals));
      value = trim_line_blanks(text.substr(equals + 1));
    } else {
      const std::size_t blank = text.find_first_of(" \t");
      key = text.substr(0, blank);
      value = blank == std::string_view::npos ? std::string_view()
                                              : trim_line_blanks(text.substr(blank));
    }
    const HeaderKey kind = classify(key);
    if (first && equals == std::string_view::npos && (kind == HeaderKey::kOther || value.empty())) {
      out_.name = std::string(text);  // OpenSim storage: the first line is the bare name
      return;
    }
    switch (kind) {
      case HeaderKey::kName:
        out_.name = std::string(value);
        break;
      case HeaderKey::kVersion: {
        int version = 0;
        if (!parse_int_token(value, version) || version < 0) {
          fail(line.number, key,
               "expected a version number such as 1, got " + quote_for_message(value));
        }
        break;
      }
      case HeaderKey::kRows:
      case HeaderKey::kColumns: {
        int count = 0;
        if (!parse_int_token(value, count) || count < 0) {
          fail(line.number, key, "expected a count >= 0, got " + quote_for_message(value));
        }
        if (ascii_lower(key).rfind("data", 0) == 0) simm_header_ = true;
        (kind == HeaderKey::kRows ? rows_ : columns_)
            .push_back({std::string(key), count, line.number});
        break;
      }
      case HeaderKey::kInDegrees: {
        const std::string flag = ascii_lower(value);
        if (flag == "yes" || flag == "true") {
          out_.in_degrees = true;
        } else if (flag == "no" || flag == "false") {
          out_.in_degrees = false;
        } else {
          fail(line.number, key, "expected yes or no, got " + quote_for_message(value));
        }
        out_.in_degrees_stated = true;
        break;
      }
      case HeaderKey::kDataType:
        if (ascii_lower(value) != "double") {
          fail(line.number, key,
               "expected DataType=double, got " + quote_for_message(value) +
                   "; tables of Vec3/Quaternion/SpatialVec columns are not read here");
        }
        break;
      case HeaderKey::kOther:
        break;
    }
  }

  // Parses the label line (the first non-blank line at or after `index`);
  // returns the index of the line after it.
  std::size_t parse_labels(std::size_t index) {
    while (index < lines_.size() && trim_line_blanks(lines_[index].text).empty()) ++index;
    const int after_header = index > 0 ? lines_[index - 1].number : 0;
    if (index == lines_.size()) {
      fail(after_header,
           "the file ends after 'endheader'; expected a line of column labels "
           "starting with 'time'");
    }
    const TextLine& line = lines_[index];
    std::vector<std::string_view> labels;
    split_line_words(line.text, labels);
    if (ascii_lower(labels.front()) != "time") {
      fail(line.number, labels.front(),
           "expected 'time' as the first column label, got " + quote_for_message(labels.front()) +
               "; hint: OpenSim needs the time in the first column");
    }
    labels_line_ = line.number;
    std::map<std::string_view, int> counts;
    for (std::size_t i = 1; i < labels.size(); ++i) {
      out_.column_names.emplace_back(labels[i]);
      ++counts[labels[i]];
    }
    for (const auto& [label, count] : counts) {
      if (count > 1) {
        out_.warnings.push_back("line " + std::to_string(line.number) + ": column " +
                                quote_for_message(label) + " appears " + std::to_string(count) +
                                " times; column() returns the first");
      }
    }
    for (const Announced& columns : columns_) {
      if (columns.value != static_cast<int>(labels.size())) {
        fail(columns.line, columns.key,
             "the header announces " + std::to_string(columns.value) + " columns but line " +
                 std::to_string(line.number) + " has " + std::to_string(labels.size()) +
                 " labels (time included); hint: the column count counts the time column");
      }
    }
    return index + 1;
  }

  void parse_rows(std::size_t first) {
    const std::size_t width = out_.column_names.size() + 1;
    std::vector<std::string_view> fields;
    int previous_line = 0;
    double previous_time = 0.0;
    for (std::size_t i = first; i < lines_.size(); ++i) {
      const TextLine& line = lines_[i];
      split_line_words(line.text, fields);
      if (fields.empty()) continue;
      if (fields.size() != width) {
        fail(line.number, "the row has " + std::to_string(fields.size()) +
                              " values, expected one per column label (" + std::to_string(width) +
                              ", time included, line " + std::to_string(labels_line_) + ")");
      }
      double time = 0.0;
      if (!parse_double_token(fields[0], time)) {
        fail(line.number, "time",
             "expected a number of seconds, got " + quote_for_message(fields[0]));
      }
      if (!std::isfinite(time)) {
        fail(line.number, "time", "expected a finite time, got " + quote_for_message(fields[0]));
      }
      if (previous_line > 0 && !(time > previous_time)) {
        fail(line.number, "time",
             "time " + shortest_double_text(time) + " s does not increase, expected more than " +
                 shortest_double_text(previous_time) + " s (line " + std::to_string(previous_line) +
                 "); hint: duplicated or unsorted rows");
      }
      previous_line = line.number;
      previous_time = time;
      times_.push_back(time);
      for (std::size_t c = 1; c < width; ++c) {
        double value = 0.0;
        if (!parse_double_token(fields[c], value)) {
          fail(line.number, out_.column_names[c - 1],
               "expected a number (or NaN), got " + quote_for_message(fields[c]));
        }
        values_.push_back(value);
      }
    }
    if (times_.empty()) {
      fail(labels_line_, "no data rows after the column labels; expected one row per time");
    }
  }

  void finish() {
    const auto rows = static_cast<Eigen::Index>(times_.size());
    const auto columns = static_cast<Eigen::Index>(out_.column_names.size());
    out_.times = Eigen::Map<const Eigen::VectorXd>(times_.data(), rows);
    out_.values =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            values_.data(), rows, columns);
    for (const Announced& announced : rows_) {
      if (announced.value != rows) {
        out_.warnings.push_back("line " + std::to_string(announced.line) + ": " + announced.key +
                                " says " + std::to_string(announced.value) + " but the file has " +
                                std::to_string(rows) + " data rows; the data rows are used");
      }
    }
    if (!out_.in_degrees_stated) {
      out_.in_degrees = simm_header_ || options_.in_degrees_if_unstated;
      out_.warnings.push_back(std::string("the header does not state inDegrees; taken as ") +
                              (out_.in_degrees ? "yes" : "no") +
                              (simm_header_
                                   ? " (a SIMM motion header: SIMM stores angles in degrees)"
                                   : " (StorageReadOptions::in_degrees_if_unstated)"));
    }
  }

  std::filesystem::path name_;
  StorageReadOptions options_;
  std::vector<TextLine> lines_;
  StorageTable out_;
  bool simm_header_ = false;
  std::vector<Announced> rows_;
  std::vector<Announced> columns_;
  int labels_line_ = 0;
  std::vector<double> times_;
  std::vector<double> values_;  // row-major #rows by #columns
};

void check_for_writing(const StorageTable& table, const StorageWriteOptions& options) {
  const auto fail = [](const std::string& problem) {
    throw InvalidInputError("write_mot: " + problem);
  };
  if (options.decimals > kMaxMotDecimals) {
    fail("decimals " + std::to_string(options.decimals) + " exceeds " +
         std::to_string(kMaxMotDecimals) + "; use a negative value for exact round trips");
  }
  const Eigen::Index rows = table.times.size();
  if (table.values.rows() != rows || table.values.cols() != table.num_columns()) {
    fail("values is " + std::to_string(table.values.rows()) + " by " +
         std::to_string(table.values.cols()) + ", expected #times (" + std::to_string(rows) +
         ") by #column_names (" + std::to_string(table.num_columns()) + ")");
  }
  for (Eigen::Index r = 0; r < rows; ++r) {
    if (!std::isfinite(table.times(r)) || (r > 0 && !(table.times(r) > table.times(r - 1)))) {
      fail("times must be finite and strictly increasing; row " + std::to_string(r) + " has " +
           shortest_double_text(table.times(r)) + " s");
    }
  }
  for (const std::string& column : table.column_names) {
    if (column.empty() || column.find_first_of(" \t\r\n\v\f") != std::string::npos ||
        ascii_lower(column) == "time") {
      fail("column name " + quote_for_message(column) +
           " is empty, 'time' or contains blanks; readers split labels at blanks");
    }
  }
  if (table.name.find_first_of("=\r\n") != std::string::npos ||
      ascii_lower(trim_line_blanks(table.name)) == "endheader") {
    fail("table name " + quote_for_message(table.name) +
         " contains '=' or a line break or is 'endheader'; it would be read as a header key");
  }
}

// Index of the first column named `column_name`; throws InvalidInputError
// listing the columns when there is none.
Eigen::Index require_column(const StorageTable& table, std::string_view column_name) {
  const std::optional<Eigen::Index> index = table.column_index(column_name);
  if (index) return *index;
  const std::vector<std::string>& names = table.column_names;
  std::string listed;
  for (std::size_t i = 0; i < names.size() && i < kMaxListed; ++i) {
    listed += (i > 0 ? ", " : "") + names[i];
  }
  if (names.size() > kMaxListed) listed += ", ...";
  throw InvalidInputError(table.source.string() + ": no column " + quote_for_message(column_name) +
                          "; the " + std::to_string(names.size()) + " columns are " + listed);
}

}  // namespace

std::optional<Eigen::Index> StorageTable::column_index(std::string_view column_name) const {
  const auto it = std::find(column_names.begin(), column_names.end(), column_name);
  if (it == column_names.end()) return std::nullopt;
  return static_cast<Eigen::Index>(std::distance(column_names.begin(), it));
}

Eigen::VectorXd StorageTable::column(std::string_view column_name) const {
  return values.col(require_column(*this, column_name));
}

Eigen::RowVectorXd StorageTable::interpolate(double t) const {
  const Eigen::Index rows = times.size();
  if (rows == 0 || values.rows() != rows || !std::isfinite(t) || t < times(0) ||
      t > times(rows - 1)) {
    throw InvalidInputError(source.string() + ": time " + shortest_double_text(t) +
                            " s is outside the table's " +
                            (rows == 0 ? std::string("empty range")
                                       : "range [" + shortest_double_text(times(0)) + ", " +
                                             shortest_double_text(times(rows - 1)) + "] s") +
                            "; no extrapolation");
  }
  const double* begin = times.data();
  const double* end = begin + rows;
  const auto upper = static_cast<Eigen::Index>(std::lower_bound(begin, end, t) - begin);
  if (times(upper) == t) return values.row(upper);
  const Eigen::Index below = upper - 1;
  const double w = (t - times(below)) / (times(upper) - times(below));
  return (1.0 - w) * values.row(below) + w * values.row(upper);
}

double StorageTable::value_at(std::string_view column_name, double t) const {
  const Eigen::Index index = require_column(*this, column_name);
  return interpolate(t)(index);
}

StorageTable read_mot(const std::filesystem::path& file, const StorageReadOptions& options) {
  return parse_mot(read_whole_text_file(file, "a .mot or .sto file"), file, options);
}

StorageTable parse_mot(std::string_view text, const std::filesystem::path& name_for_messages,
                       const StorageReadOptions& options) {
  return MotParser(text, name_for_messages, options).parse();
}

void write_mot(const StorageTable& table, const std::filesystem::path& file,
               const StorageWriteOptions& options) {
  check_for_writing(table, options);
  const Eigen::Index rows = table.times.size();
  const Eigen::Index columns = table.num_columns();
  std::string out;
  out.reserve(static_cast<std::size_t>(rows * (columns + 1) * 12 + 512));
  const std::string name = trim_line_blanks(table.name).empty()
                               ? file.stem().string()
                               : std::string(trim_line_blanks(table.name));
  out += name + "\nversion=1\nnRows=" + std::to_string(rows) +
         "\nnColumns=" + std::to_string(columns + 1) +
         "\ninDegrees=" + (table.in_degrees ? "yes" : "no") + "\nendheader\ntime";
  for (const std::string& column : table.column_names) out += "\t" + column;
  out += '\n';
  for (Eigen::Index r = 0; r < rows; ++r) {
    append_number_text(out, table.times(r), options.decimals);
    for (Eigen::Index c = 0; c < columns; ++c) {
      out += '\t';
      append_number_text(out, table.values(r, c), options.decimals);
    }
    out += '\n';
  }
  std::ofstream stream(file, std::ios::binary | std::ios::trunc);
  if (!stream) {
    throw IoError(file,
                  "cannot be opened for writing; check that the folder exists and is "
                  "writable");
  }
  stream.write(out.data(), static_cast<std::streamsize>(out.size()));
  stream.close();
  if (!stream) throw IoError(file, "write failed (disk full?)");
}

}  // namespace mmm::opensim

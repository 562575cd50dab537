#include "core/opensim/trc.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
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

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Header lines before the data: PathFileType, keys, values, names, X/Y/Z labels.
constexpr int kHeaderLines = 5;
constexpr int kMaxTrcDecimals = 20;

bool is_blank_line(std::string_view line) { return trim_line_blanks(line).empty(); }

// Fields of a line: at tabs when the line has one (an empty field is kept,
// it marks a missing value), otherwise at runs of spaces. Fields are trimmed.
void split_fields(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  if (line.find('\t') != std::string_view::npos) {
    std::size_t start = 0;
    while (true) {
      const std::size_t tab = line.find('\t', start);
      const std::size_t end = tab == std::string_view::npos ? line.size() : tab;
      fields.push_back(trim_line_blanks(line.substr(start, end - start)));
      if (tab == std::string_view::npos) break;
      start = tab + 1;
    }
    return;
  }
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && is_line_blank(line[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < line.size() && !is_line_blank(line[pos])) ++pos;
    if (pos > start) fields.push_back(line.substr(start, pos - start));
  }
}

// The non-empty fields of a header line.
std::vector<std::string_view> header_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  split_fields(line, fields);
  fields.erase(std::remove_if(fields.begin(), fields.end(),
                              [](std::string_view field) { return field.empty(); }),
               fields.end());
  return fields;
}

// Millimetres per unit for the spellings of mm, cm and m; nullopt otherwise.
std::optional<double> millimetres_per_unit(std::string_view units) {
  const std::string key = ascii_lower(units);
  if (key == "mm" || key == "millimeters" || key == "millimetres") return 1.0;
  if (key == "cm" || key == "centimeters" || key == "centimetres") return 10.0;
  if (key == "m" || key == "meters" || key == "metres") return 1000.0;
  return std::nullopt;
}

class TrcParser {
 public:
  TrcParser(std::string_view text, std::filesystem::path name)
      : name_(std::move(name)), lines_(split_text_lines(text)) {}

  MarkerTrajectories parse() {
    out_.source = name_;
    parse_magic();
    parse_keys_and_values();
    parse_names();
    parse_coordinate_labels();
    parse_data();
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

  // Header line `index` (1-based); fails when the file ends before it.
  const TextLine& header_line(int index, std::string_view expected) const {
    if (static_cast<int>(lines_.size()) < index) {
      fail(index, "the file ends before header line " + std::to_string(index) + " (" +
                      std::string(expected) + "); a .trc file has 5 header lines before the data");
    }
    return lines_[static_cast<std::size_t>(index - 1)];
  }

  void parse_magic() {
    if (lines_.empty()) {
      throw IoError(name_, "the file is empty, expected a .trc file starting with 'PathFileType'");
    }
    const std::vector<std::string_view> fields = header_fields(lines_[0].text);
    if (fields.empty() || fields[0] != "PathFileType") {
      fail(1, "expected 'PathFileType' as the first word of a .trc file, got " +
                  (fields.empty() ? std::string("an empty line") : quote_for_message(fields[0])) +
                  "; hint: is this a .trc file (a .mot/.sto or C3D file needs another reader)?");
    }
  }

  void parse_keys_and_values() {
    const TextLine& key_line = header_line(2, "DataRate CameraRate NumFrames NumMarkers Units ...");
    const TextLine& value_line = header_line(3, "the values of the header keys");
    const std::vector<std::string_view> keys = header_fields(key_line.text);
    const std::vector<std::string_view> values = header_fields(value_line.text);
    if (keys.size() != values.size()) {
      fail(value_line.number,
           "the header has " + std::to_string(keys.size()) + " keys on line " +
               std::to_string(key_line.number) + " but " + std::to_string(values.size()) +
               " values; expected one value per key (DataRate CameraRate NumFrames NumMarkers "
               "Units OrigDataRate OrigDataStartFrame OrigNumFrames)");
    }
    bool has_camera_rate = false;
    bool has_orig_rate = false;
    bool has_orig_frames = false;
    std::set<std::string> seen;
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const std::string key = ascii_lower(keys[i]);
      const std::string_view value = values[i];
      if (!seen.insert(key).second) {
        fail(key_line.number, keys[i], "the header key appears twice; expected each key once");
      }
      if (key == "datarate") {
        out_.data_rate = header_rate(value_line.number, keys[i], value);
      } else if (key == "camerarate") {
        out_.camera_rate = header_rate(value_line.number, keys[i], value);
        has_camera_rate = true;
      } else if (key == "origdatarate") {
        out_.orig_data_rate = header_rate(value_line.number, keys[i], value);
        has_orig_rate = true;
      } else if (key == "numframes") {
        header_num_frames_ = header_count(value_line.number, keys[i], value);
        has_num_frames_ = true;
      } else if (key == "nummarkers") {
        header_num_markers_ = header_count(value_line.number, keys[i], value);
      } else if (key == "origdatastartframe") {
        out_.orig_data_start_frame = header_integer(value_line.number, keys[i], value);
      } else if (key == "orignumframes") {
        out_.orig_num_frames = header_count(value_line.number, keys[i], value);
        has_orig_frames = true;
      } else if (key == "units") {
        const std::optional<double> factor = millimetres_per_unit(value);
        if (!factor) {
          fail(value_line.number, keys[i],
               "unknown length unit " + quote_for_message(value) + ", expected mm, cm or m");
        }
        out_.units = std::string(value);
        out_.unit_to_mm = *factor;
      } else {
        out_.warnings.push_back("line " + std::to_string(key_line.number) +
                                ": unknown header key " + quote_for_message(keys[i]) + " ignored");
      }
    }
    for (const auto* required : {"datarate", "numframes", "nummarkers", "units"}) {
      if (!seen.contains(required)) {
        fail(key_line.number, "the header has no " + std::string(required) +
                                  " key (case-insensitive); expected the keys DataRate "
                                  "CameraRate NumFrames NumMarkers Units OrigDataRate "
                                  "OrigDataStartFrame OrigNumFrames");
      }
    }
    if (!has_camera_rate) out_.camera_rate = out_.data_rate;
    if (!has_orig_rate) out_.orig_data_rate = out_.data_rate;
    orig_frames_given_ = has_orig_frames;
  }

  double header_rate(int line, std::string_view key, std::string_view value) const {
    double rate = 0.0;
    if (!parse_double_token(value, rate) || !std::isfinite(rate) || rate <= 0.0) {
      fail(line, key, "expected a positive rate in Hz, got " + quote_for_message(value));
    }
    return rate;
  }

  int header_integer(int line, std::string_view key, std::string_view value) const {
    int number = 0;
    if (!parse_int_token(value, number))
      fail(line, key, "expected an integer, got " + quote_for_message(value));
    return number;
  }

  int header_count(int line, std::string_view key, std::string_view value) const {
    const int count = header_integer(line, key, value);
    if (count < 0) fail(line, key, "expected a count >= 0, got " + quote_for_message(value));
    return count;
  }

  void parse_names() {
    const TextLine& line = header_line(4, "Frame# Time and the marker names");
    const std::vector<std::string_view> fields = header_fields(line.text);
    if (fields.size() < 2 || ascii_lower(fields[0]) != "frame#" ||
        ascii_lower(fields[1]) != "time") {
      fail(line.number,
           "expected the column labels 'Frame#' and 'Time' followed by the marker "
           "names, got " +
               (fields.empty() ? std::string("an empty line") : quote_for_message(line.text)));
    }
    const auto num_names = static_cast<int>(fields.size()) - 2;
    if (num_names != header_num_markers_) {
      fail(line.number, "the header says NumMarkers " + std::to_string(header_num_markers_) +
                            " but this line names " + std::to_string(num_names) +
                            " markers; hint: a marker name with a space in a space-separated "
                            "file, or a stale NumMarkers");
    }
    std::set<std::string_view> seen;
    for (std::size_t i = 2; i < fields.size(); ++i) {
      if (!seen.insert(fields[i]).second) {
        fail(line.number, fields[i],
             "duplicate marker name (marker " + std::to_string(i - 1) +
                 "); expected every marker named once, as the IK and Scale tools look markers up "
                 "by name");
      }
      out_.marker_names.emplace_back(fields[i]);
    }
    names_line_ = line.number;
  }

  void parse_coordinate_labels() {
    const TextLine& line = header_line(kHeaderLines, "the X1 Y1 Z1 X2 ... coordinate labels");
    const std::vector<std::string_view> fields = header_fields(line.text);
    const std::size_t expected = 3 * out_.marker_names.size();
    if (fields.size() != expected) {
      fail(line.number, "expected 3 coordinate labels (X1 Y1 Z1 ...) per marker, " +
                            std::to_string(expected) + " for the " +
                            std::to_string(out_.marker_names.size()) + " markers of line " +
                            std::to_string(names_line_) + ", got " + std::to_string(fields.size()));
    }
    labels_.assign(fields.begin(), fields.end());
  }

  // "column 'Y1' (marker 'R.ASIS')" for data column `column` (0-based field index).
  [[noreturn]] void fail_column(int line, std::size_t column, const std::string& problem) const {
    if (column < 2) fail(line, column == 0 ? "Frame#" : "Time", problem);
    const std::size_t coordinate = column - 2;
    const std::size_t marker = coordinate / 3;
    std::string where =
        "column " + quote_for_message(coordinate < labels_.size() ? labels_[coordinate] : "?");
    if (marker < out_.marker_names.size())
      where += " (marker " + quote_for_message(out_.marker_names[marker]) + ")";
    throw IoError(name_, "line " + std::to_string(line) + ", " + where + ": " + problem);
  }

  void parse_data() {
    const std::size_t num_markers = out_.marker_names.size();
    const std::size_t num_columns = 2 + 3 * num_markers;
    std::vector<std::string_view> fields;
    int previous_line = 0;
    double previous_time = 0.0;
    for (std::size_t l = kHeaderLines; l < lines_.size(); ++l) {
      const TextLine& line = lines_[l];
      if (is_blank_line(line.text)) continue;
      split_fields(line.text, fields);
      while (fields.size() > num_columns && fields.back().empty()) fields.pop_back();
      if (fields.size() > num_columns) {
        fail(line.number, "the row has " + std::to_string(fields.size()) +
                              " values but the header has " + std::to_string(num_columns) +
                              " columns (Frame#, Time and 3 per marker for " +
                              std::to_string(num_markers) +
                              " markers); hint: NumMarkers or the marker names are incomplete");
      }
      if (fields.size() < num_columns) ++short_rows_;
      out_.frame_numbers.push_back(parse_frame_number(line.number, fields));
      const double time = parse_time(line.number, fields);
      if (previous_line > 0 && !(time > previous_time)) {
        fail(line.number, "Time",
             "time " + shortest_double_text(time) + " s does not increase, expected more than " +
                 shortest_double_text(previous_time) + " s (line " + std::to_string(previous_line) +
                 "); hint: duplicated or unsorted frames");
      }
      previous_line = line.number;
      previous_time = time;
      times_.push_back(time);
      for (std::size_t m = 0; m < num_markers; ++m) {
        std::array<double, 3> xyz{};
        bool missing = false;
        for (std::size_t a = 0; a < 3; ++a) {
          const std::size_t column = 2 + 3 * m + a;
          if (column >= fields.size() || fields[column].empty()) {
            missing = true;
            continue;
          }
          if (!parse_double_token(fields[column], xyz[a])) {
            fail_column(line.number, column,
                        "expected a number or an empty field (missing marker), got " +
                            quote_for_message(fields[column]));
          }
          if (std::isinf(xyz[a])) {
            fail_column(line.number, column,
                        "expected a finite coordinate or an empty field, got " +
                            quote_for_message(fields[column]));
          }
          if (std::isnan(xyz[a])) missing = true;
        }
        for (std::size_t a = 0; a < 3; ++a) values_.push_back(missing ? kNaN : xyz[a]);
      }
    }
    if (times_.empty()) {
      fail(static_cast<int>(lines_.size()),
           "no data rows after the 5 header lines; expected one row per frame");
    }
  }

  int parse_frame_number(int line, const std::vector<std::string_view>& fields) const {
    if (fields.empty() || fields[0].empty()) {
      fail(line, "Frame#", "the frame number is missing, expected an integer");
    }
    int frame = 0;
    if (!parse_int_token(fields[0], frame)) {
      fail(line, "Frame#", "expected an integer frame number, got " + quote_for_message(fields[0]));
    }
    return frame;
  }

  double parse_time(int line, const std::vector<std::string_view>& fields) const {
    if (fields.size() < 2 || fields[1].empty()) {
      fail(line, "Time", "the time is missing, expected a number of seconds");
    }
    double time = 0.0;
    if (!parse_double_token(fields[1], time)) {
      fail(line, "Time", "expected a number of seconds, got " + quote_for_message(fields[1]));
    }
    if (!std::isfinite(time)) {
      fail(line, "Time", "expected a finite time, got " + quote_for_message(fields[1]));
    }
    return time;
  }

  void finish() {
    const auto num_frames = static_cast<Eigen::Index>(times_.size());
    const auto width = static_cast<Eigen::Index>(3 * out_.marker_names.size());
    out_.times = Eigen::Map<const Eigen::VectorXd>(times_.data(), num_frames);
    out_.positions =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            values_.data(), num_frames, width);
    if (!orig_frames_given_) out_.orig_num_frames = static_cast<int>(num_frames);
    if (has_num_frames_ && header_num_frames_ != num_frames) {
      out_.warnings.push_back("line 3: NumFrames says " + std::to_string(header_num_frames_) +
                              " but the file has " + std::to_string(num_frames) +
                              " data rows; the data rows are used");
    }
    if (short_rows_ > 0) {
      out_.warnings.push_back(
          std::to_string(short_rows_) + " data rows are shorter than the header (" +
          std::to_string(2 + width) + " columns); their missing markers are NaN");
    }
  }

  std::filesystem::path name_;
  std::vector<TextLine> lines_;
  MarkerTrajectories out_;
  int header_num_frames_ = 0;
  int header_num_markers_ = 0;
  bool has_num_frames_ = false;
  bool orig_frames_given_ = false;
  int names_line_ = 4;
  std::vector<std::string_view> labels_;  // X1 Y1 Z1 ... as written
  std::vector<double> times_;
  std::vector<double> values_;  // row-major #frames by 3 #markers
  int short_rows_ = 0;
};

void check_for_writing(const MarkerTrajectories& t, const TrcWriteOptions& options) {
  const auto fail = [](const std::string& problem) {
    throw InvalidInputError("write_trc: " + problem);
  };
  if (options.decimals > kMaxTrcDecimals) {
    fail("decimals " + std::to_string(options.decimals) + " exceeds " +
         std::to_string(kMaxTrcDecimals) + "; use a negative value for exact round trips");
  }
  const Eigen::Index num_frames = t.times.size();
  const Eigen::Index num_markers = t.num_markers();
  if (t.positions.rows() != num_frames || t.positions.cols() != 3 * num_markers) {
    fail("positions is " + std::to_string(t.positions.rows()) + " by " +
         std::to_string(t.positions.cols()) + ", expected #times (" + std::to_string(num_frames) +
         ") by 3 #markers (" + std::to_string(3 * num_markers) + ")");
  }
  if (static_cast<Eigen::Index>(t.frame_numbers.size()) != num_frames) {
    fail("frame_numbers has " + std::to_string(t.frame_numbers.size()) + " entries, expected " +
         std::to_string(num_frames) + " (one per time)");
  }
  if (!std::isfinite(t.data_rate) || t.data_rate <= 0.0) {
    fail("data_rate " + shortest_double_text(t.data_rate) + " Hz is not a positive number");
  }
  if (!millimetres_per_unit(t.units)) {
    fail("units " + quote_for_message(t.units) + " is not one of mm, cm, m");
  }
  std::set<std::string_view> seen;
  for (const std::string& name : t.marker_names) {
    if (name.empty() || name.find_first_of("\t\r\n") != std::string::npos ||
        trim_line_blanks(name) != name) {
      fail("marker name " + quote_for_message(name) +
           " is empty, has surrounding blanks or contains a tab or line break");
    }
    if (!seen.insert(name).second)
      fail("marker name " + quote_for_message(name) + " appears twice");
  }
  for (Eigen::Index f = 0; f < num_frames; ++f) {
    if (!std::isfinite(t.times(f)) || (f > 0 && !(t.times(f) > t.times(f - 1)))) {
      fail("times must be finite and strictly increasing; frame " + std::to_string(f) + " has " +
           shortest_double_text(t.times(f)) + " s");
    }
  }
  if (t.positions.array().isInf().any()) fail("positions contain an infinite value");
}

}  // namespace

std::optional<Eigen::Index> MarkerTrajectories::marker_index(std::string_view name) const {
  const auto it = std::find(marker_names.begin(), marker_names.end(), name);
  if (it == marker_names.end()) return std::nullopt;
  return static_cast<Eigen::Index>(std::distance(marker_names.begin(), it));
}

Eigen::Vector3d MarkerTrajectories::position(Eigen::Index frame, Eigen::Index marker) const {
  if (frame < 0 || frame >= num_frames() || marker < 0 || marker >= num_markers() ||
      positions.cols() != 3 * num_markers()) {
    throw InvalidInputError("MarkerTrajectories::position: frame " + std::to_string(frame) +
                            ", marker " + std::to_string(marker) + " is out of range (" +
                            std::to_string(num_frames()) + " frames, " +
                            std::to_string(num_markers()) + " markers)");
  }
  return positions.block<1, 3>(frame, 3 * marker).transpose();
}

std::optional<Eigen::Index> MarkerTrajectories::frame_at_time(double t) const {
  if (!std::isfinite(t) || times.size() == 0) return std::nullopt;
  const double slack = data_rate > 0.0 ? 0.5 / data_rate : 0.0;
  if (t < times(0) - slack || t > times(times.size() - 1) + slack) return std::nullopt;
  const double* begin = times.data();
  const double* end = begin + times.size();
  const double* upper = std::lower_bound(begin, end, t);
  if (upper == begin) return 0;
  if (upper == end) return times.size() - 1;
  const double* below = upper - 1;
  const double* nearest = (t - *below) <= (*upper - t) ? below : upper;
  return static_cast<Eigen::Index>(nearest - begin);
}

Eigen::Index MarkerTrajectories::count_missing() const {
  Eigen::Index missing = 0;
  for (Eigen::Index m = 0; m < num_markers() && 3 * m < positions.cols(); ++m) {
    missing += positions.col(3 * m).array().isNaN().count();
  }
  return missing;
}

MarkerTrajectories read_trc(const std::filesystem::path& file) {
  return parse_trc(read_whole_text_file(file, "a .trc file"), file);
}

MarkerTrajectories parse_trc(std::string_view text,
                             const std::filesystem::path& name_for_messages) {
  return TrcParser(text, name_for_messages).parse();
}

void write_trc(const MarkerTrajectories& trajectories, const std::filesystem::path& file,
               const TrcWriteOptions& options) {
  check_for_writing(trajectories, options);
  const MarkerTrajectories& t = trajectories;
  const Eigen::Index num_frames = t.times.size();
  const Eigen::Index num_markers = t.num_markers();
  std::string out;
  out.reserve(static_cast<std::size_t>(num_frames * (3 * num_markers + 2) * 12 + 1024));
  out += "PathFileType\t4\t(X/Y/Z)\t" + file.filename().string() + "\n";
  out +=
      "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame"
      "\tOrigNumFrames\n";
  const double camera_rate = t.camera_rate > 0.0 ? t.camera_rate : t.data_rate;
  const double orig_rate = t.orig_data_rate > 0.0 ? t.orig_data_rate : t.data_rate;
  out += shortest_double_text(t.data_rate) + "\t" + shortest_double_text(camera_rate) + "\t" +
         std::to_string(num_frames) + "\t" + std::to_string(num_markers) + "\t" + t.units + "\t" +
         shortest_double_text(orig_rate) + "\t" + std::to_string(t.orig_data_start_frame) + "\t" +
         std::to_string(t.orig_num_frames > 0 ? t.orig_num_frames : num_frames) + "\n";
  out += "Frame#\tTime";
  for (const std::string& name : t.marker_names) out += "\t" + name + "\t\t";
  out += "\n\t";
  for (Eigen::Index m = 1; m <= num_markers; ++m) {
    const std::string index = std::to_string(m);
    for (const char axis : {'X', 'Y', 'Z'}) {
      out += '\t';
      out += axis;
      out += index;
    }
  }
  out += "\n\n";
  for (Eigen::Index f = 0; f < num_frames; ++f) {
    out += std::to_string(t.frame_numbers[static_cast<std::size_t>(f)]);
    out += '\t';
    append_number_text(out, t.times(f), options.decimals);
    for (Eigen::Index c = 0; c < 3 * num_markers; ++c) {
      out += '\t';
      const double value = t.positions(f, c);
      if (!std::isnan(value)) append_number_text(out, value, options.decimals);
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

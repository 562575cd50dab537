#pragma once
// OpenSim storage files (.mot, .sto): a header ending in "endheader", a line
// of column labels starting with "time", then one row of numbers per time:
//
//   ik_result                 <- name (SIMM motion files: "name ik_result")
//   version=1
//   nRows=211
//   nColumns=24               <- counts the time column
//   inDegrees=yes
//   endheader
//   time  pelvis_tilt  ...  knee_angle_r  ...
//   0.5   4.83         ...  -19.88        ...
//
// The reader also takes the SIMM motion header OpenSim 3 wrote ("# SIMM
// Motion File Header", "datacolumns 165", "datarows 211", "range 0.5 4").
// Fields are separated by tabs and/or spaces.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::opensim {

// A table of samples over time, in the units of the file: OpenSim writes
// lengths in m, and angles in degrees when in_degrees, else in radians.
struct StorageTable {
  std::filesystem::path source;  // the file read (or the name given to parse_mot)
  std::string name;              // first header line ("name X" in SIMM headers); may be empty
  // True when rotational columns hold degrees. From the header's inDegrees
  // when stated (in_degrees_stated); otherwise inferred, see read_mot.
  bool in_degrees = false;
  bool in_degrees_stated = false;
  std::vector<std::string> column_names;  // #columns, without "time"; names may repeat
  Eigen::VectorXd times;                  // #rows, strictly increasing (s)
  Eigen::MatrixXd values;                 // #rows by #columns; NaN/inf kept as written
  // Tolerated oddities, one sentence each (nRows disagreeing with the data,
  // repeated column names, an inferred inDegrees). Empty for a clean file.
  std::vector<std::string> warnings;

  [[nodiscard]] Eigen::Index num_rows() const { return values.rows(); }
  [[nodiscard]] Eigen::Index num_columns() const {
    return static_cast<Eigen::Index>(column_names.size());
  }
  // Index of the first column with this exact name, or nullopt.
  [[nodiscard]] std::optional<Eigen::Index> column_index(std::string_view column_name) const;
  // The #rows values of the first column with this name. Throws
  // InvalidInputError naming the available columns when there is none.
  [[nodiscard]] Eigen::VectorXd column(std::string_view column_name) const;
  // All columns at time t (s), linearly interpolated between the two rows
  // around t (exactly a row at its time): a 1 by #columns row. Throws
  // InvalidInputError when t is not finite or lies outside
  // [times(0), times(last)] (no extrapolation).
  [[nodiscard]] Eigen::RowVectorXd interpolate(double t) const;
  // One column at time t, as interpolate(t) does; throws like column() and
  // interpolate().
  [[nodiscard]] double value_at(std::string_view column_name, double t) const;
};

struct StorageReadOptions {
  // Used when the header does not state inDegrees and is not a SIMM motion
  // header (those store angles in degrees, so they read as in_degrees). The
  // default false matches OpenSim 4, which takes only an explicit
  // "inDegrees=yes" for degrees.
  bool in_degrees_if_unstated = false;
};

// Reads a .mot or .sto file.
//
// Header: lines up to "endheader". The first line is the name unless it is a
// key; then "key=value" or SIMM "key value" lines: version, nRows / datarows
// / nr, nColumns / datacolumns / nc, inDegrees (yes/no/true/false), DataType
// (only "double"); others and "#" comments are ignored. When inDegrees is
// absent, a SIMM motion header ("datarows"/"datacolumns" keys or a "# SIMM"
// comment) means degrees, else options.in_degrees_if_unstated; either way a
// warning says so. nRows that disagrees with the data rows is warned about
// (the data win); repeated column names are warned about and kept.
//
// Throws IoError(file, "line N[, column 'X']: what, expected vs got; hint")
// for: a missing or unreadable file; no "endheader" line (hint when the file
// is a .trc); a first label other than "time"; nColumns not equal to the
// number of labels (time included); a bad inDegrees, version, count or
// DataType value; an empty label; a row with a different number of fields
// than labels; a field that is not a number (naming the line and column); a
// time that is NaN, infinite or not strictly increasing; no data rows.
StorageTable read_mot(const std::filesystem::path& file, const StorageReadOptions& options = {});

// Same, from the text in memory; `name_for_messages` is the path put in error
// messages and in StorageTable::source.
StorageTable parse_mot(std::string_view text, const std::filesystem::path& name_for_messages,
                       const StorageReadOptions& options = {});

struct StorageWriteOptions {
  // Digits after the decimal point. Negative (the default): the shortest text
  // that reads back to the identical double, so write -> read is exact.
  int decimals = -1;
};

// Writes `table` in the OpenSim 4 storage layout, tab-separated:
//   <name>, version=1, nRows=R, nColumns=C+1, inDegrees=yes|no, endheader,
//   time<TAB>column names, then one row per time.
// The name line is table.name, or the file's stem when that is empty. NaN is
// written as "NaN".
//
// Throws InvalidInputError when the table is inconsistent (values not
// #times by #column_names; times not finite and strictly increasing; a
// column name that is empty, "time" or contains blanks; a name containing
// '=' or a line break, or equal to "endheader") and IoError when the file
// cannot be written.
void write_mot(const StorageTable& table, const std::filesystem::path& file,
               const StorageWriteOptions& options = {});

}  // namespace mmm::opensim

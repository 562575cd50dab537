#pragma once
// Marker trajectories in the TRC format (Motion Analysis "PathFileType 4
// (X/Y/Z)"), the marker input of OpenSim's Scale and IK tools:
//
//   PathFileType  4  (X/Y/Z)  subject01_walk1.trc
//   DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame
//   OrigNumFrames 60.00     60.00       151        41          mm     60.00         1 151 Frame#
//   Time  R.ASIS        L.ASIS        ...
//                 X1  Y1  Z1    X2  Y2  Z2    ...
//   <blank line>
//   1  0.000000  617.2  1055.3  170.8  639.6  1044.3  -88.9  ...
//
// Fields are separated by tabs (then an empty field is a missing value) or,
// in a line without tabs, by runs of spaces.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::opensim {

// One motion-capture trial, in the units of the file.
//
// Layout of `positions`: one Eigen::MatrixXd with a row per frame and three
// columns per marker, in file order (the layout of the file's data rows):
// marker m of frame f is positions(f, 3m + 0..2) = (X, Y, Z). A column is
// one coordinate of one marker over time, so middleCols(3m, 3) is the
// #frames by 3 trajectory of marker m.
//
// Missing samples are NaN. A marker whose X, Y or Z is missing in a frame
// (empty field, "NaN", or a data row shorter than the header) is missing as
// a whole: all three of its coordinates are NaN in that frame.
struct MarkerTrajectories {
  std::filesystem::path source;           // the file read (or the name given to parse_trc)
  double data_rate = 0.0;                 // DataRate (Hz)
  double camera_rate = 0.0;               // CameraRate (Hz); DataRate when the header has none
  double orig_data_rate = 0.0;            // OrigDataRate (Hz); DataRate when the header has none
  int orig_data_start_frame = 1;          // OrigDataStartFrame; 1 when the header has none
  int orig_num_frames = 0;                // OrigNumFrames; the frame count when the header has none
  std::string units;                      // Units as written: "mm", "cm" or "m" (any letter case)
  double unit_to_mm = 1.0;                // multiply positions by this to get mm (1, 10 or 1000)
  std::vector<std::string> marker_names;  // #markers, file order, unique
  std::vector<int> frame_numbers;         // #frames, the Frame# column
  Eigen::VectorXd times;                  // #frames, the Time column (s), strictly increasing
  Eigen::MatrixXd positions;              // #frames by 3 #markers (units; NaN = missing)
  // Tolerated oddities, one sentence each (NumFrames disagreeing with the
  // data, rows shorter than the header, ...). Empty for a clean file.
  std::vector<std::string> warnings;

  [[nodiscard]] Eigen::Index num_frames() const { return positions.rows(); }
  [[nodiscard]] Eigen::Index num_markers() const {
    return static_cast<Eigen::Index>(marker_names.size());
  }
  // Index of the marker with this exact name, or nullopt.
  [[nodiscard]] std::optional<Eigen::Index> marker_index(std::string_view name) const;
  // Position of `marker` in `frame` (units; NaN when missing). Both indices
  // 0-based; throws InvalidInputError when out of range.
  [[nodiscard]] Eigen::Vector3d position(Eigen::Index frame, Eigen::Index marker) const;
  // Index of the frame whose time is nearest to t (s), or nullopt when t lies
  // outside [times(0), times(last)] by more than half a frame period
  // (1 / (2 data_rate)) or is not finite. Binary search.
  [[nodiscard]] std::optional<Eigen::Index> frame_at_time(double t) const;
  // Number of missing (NaN) marker samples, counting a missing marker once per frame.
  [[nodiscard]] Eigen::Index count_missing() const;
};

// Reads a .trc file.
//
// Tolerated (and, where noted, reported in `warnings`): tabs or spaces as
// separators, CRLF line ends, trailing empty fields, blank lines, data rows
// shorter than the header (missing values, warned once), a NumFrames that
// disagrees with the data rows (the data wins, warned), missing CameraRate /
// OrigDataRate / OrigDataStartFrame / OrigNumFrames keys.
//
// Throws IoError(file, "line N[, column 'X']: what, expected vs got; hint")
// for: a missing or unreadable file; a first line not starting with
// "PathFileType"; a key line and a value line of different lengths; a
// missing DataRate, NumFrames, NumMarkers or Units key; a non-positive
// DataRate; Units other than mm, cm, m; a marker-name count that differs
// from NumMarkers; an X/Y/Z label line whose count is not 3 per marker;
// duplicate or empty marker names; a non-numeric or non-integer field
// (naming the line and the column label); a data row with more non-empty
// fields than the header has columns; a NaN or infinite time; times that do
// not strictly increase; no data rows.
MarkerTrajectories read_trc(const std::filesystem::path& file);

// Same, from the text in memory; `name_for_messages` is the path put in error
// messages and in MarkerTrajectories::source.
MarkerTrajectories parse_trc(std::string_view text, const std::filesystem::path& name_for_messages);

struct TrcWriteOptions {
  // Digits after the decimal point for positions and times. Negative (the
  // default): the shortest text that reads back to the identical double, so
  // write -> read is exact.
  int decimals = -1;
};

// Writes `trajectories` as a tab-separated .trc file that OpenSim reads:
// the 5 header lines above, a blank line, then one row per frame. NaN
// positions are written as empty fields (the TRC convention for a missing
// marker). NumFrames and NumMarkers are taken from the data, the file's own
// name is put on the first line.
//
// Throws InvalidInputError when the data are inconsistent (sizes of
// marker_names / frame_numbers / times / positions disagree, a marker name is
// empty, repeated or contains a tab or line break, the units are not mm, cm
// or m, times are not finite and strictly increasing, a position is
// infinite) and IoError when the file cannot be written.
void write_trc(const MarkerTrajectories& trajectories, const std::filesystem::path& file,
               const TrcWriteOptions& options = {});

}  // namespace mmm::opensim

#pragma once
// Which trial marker drives which model marker, and how much: the marker
// tasks of inverse kinematics, plus coordinate tasks that hold a coordinate
// the markers cannot resolve near a value. A YAML file (schema in
// schemas/motion/gait2392_marker_mapping.yaml, the mapping shipped for
// OpenSim's gait2392 marker set with its IK weights):
//
//   mmm_marker_mapping: 1
//   name: gait2392
//   markers:
//     - {trial: R.ASIS, weight: 10}            # model marker of the same name
//     - {trial: RASI, model: R.ASIS, weight: 10}
//   coordinates:
//     - {name: subtalar_angle_r, value: 0, weight: 1000}   # value: deg (angles) or mm
//
// Weights mean what OpenSim's mean: a marker's squared error in m times its
// weight, a coordinate's squared error in rad (or m) times its weight.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::motion {

struct MarkerTask {
  std::string trial;  // marker name in the .trc
  std::string model;  // marker name on the model (the trial name when not given)
  double weight = 1.0;
};

struct CoordinateTask {
  std::string coordinate;
  double value = 0.0;  // deg for angles, mm for lengths, as written
  double weight = 1.0;
};

struct MarkerMapping {
  std::filesystem::path source;  // the file read, or the name given to parse
  std::string name;
  std::string description;
  std::vector<MarkerTask> markers;
  std::vector<CoordinateTask> coordinates;
};

// Reads a mapping file. Throws IoError(file, "line L:C: field: what; hint")
// for: a missing or unreadable file; malformed YAML; a format version other
// than 1; unknown keys (with did-you-mean); a marker without `trial`; a
// trial or model name used twice; a weight that is not a finite number
// >= 0; a coordinate task without `name`, named twice, or with a value that
// is not finite; no marker with a positive weight.
MarkerMapping read_marker_mapping(const std::filesystem::path& file);

// Same, from the text in memory; `name_for_messages` is the path put in
// error messages and in MarkerMapping::source.
MarkerMapping parse_marker_mapping(std::string_view text,
                                   const std::filesystem::path& name_for_messages);

// The shipped mapping for OpenSim's gait2392 marker set (compiled in).
std::string_view gait2392_marker_mapping_text();
MarkerMapping gait2392_marker_mapping();

}  // namespace mmm::motion

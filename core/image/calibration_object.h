#pragma once
// The two files of a calibration with a calibration object:
//
//   the object   {"format": "mmm-calibration-object", "version": 1,
//                 "name": "cage-2026", "beads": {"b01": [x, y, z], ...}}
//                bead centres in mm, in the frame the calibrated views will
//                use (the object's);
//   the clicks   {"format": "mmm-bead-clicks", "version": 1,
//                 "views": {"frontal": {"b01": [u, v], ...},
//                           "lateral": {...}}}
//                where an operator (or a detector) saw each bead, in pixels
//                (u right, v down, pixel centres at +0.5); a bead may be
//                missing from a view (hidden behind another).
//
// Both are parsed within core/bounded_json.h's limits (and at most 1 MiB);
// every error is an IoError naming the file and the field, e.g.
// "views.frontal.b07: unknown bead (the object has b01-b24)".

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

namespace mmm::image {

struct CalibrationObject {
  std::string name;
  std::map<std::string, Eigen::Vector3d> beads;  // name -> centre (mm)
};

// Bead name -> pixel, per view name.
using BeadClicks = std::map<std::string, std::map<std::string, Eigen::Vector2d>>;

CalibrationObject parse_calibration_object(std::string_view text,
                                           const std::filesystem::path& source);
// Clicks on beads of `object` only.
BeadClicks parse_bead_clicks(std::string_view text, const std::filesystem::path& source,
                             const CalibrationObject& object);

}  // namespace mmm::image

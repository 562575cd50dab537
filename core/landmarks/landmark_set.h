#pragma once
// LandmarkSet: named 3-D points (mm) in a stated frame, the value that flows
// between workflow nodes (radiograph triangulation, Slicer markups, static
// motion-capture trials -> atlas scaling), with its canonical JSON form.
//
// JSON (keys sorted, two-space indent, numbers as the shortest text that
// reads back to the same double, so text -> set -> text is the identity):
//   {"format": "mmm-landmark-set", "version": 1,
//    "frame": "patient", "source": "radiographs",
//    "landmarks": [
//      {"name": "femoral_head_centre_r", "position_mm": [x, y, z],
//       "pixels": {"frontal": [u, v], "lateral": [u, v]},       (optional)
//       "reprojection_error_mm": {"frontal": e, "lateral": e}}, (optional)
//      ...]}
// Landmarks keep their order; "pixels" and "reprojection_error_mm" are left
// out when empty.

#include <Eigen/Core>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::landmarks {

struct Landmark {
  std::string name;  // e.g. "femoral_head_centre_r"; non-empty, unique in its set
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();  // in the set's frame (mm)
  // Triangulated landmarks: distance between the projection of position_mm
  // and the operator's pixel, per view name (mm at the isocentre plane,
  // core/image/projection.h). Empty otherwise.
  std::map<std::string, double> reprojection_error_mm;
  // Triangulated landmarks: the operator's pixel (u, v) per view name.
  std::map<std::string, Eigen::Vector2d> pixels;
};

struct LandmarkSet {
  // Frame of every position: "patient" (the RAS patient frame of
  // core/image/projection.h) or "lab" (a motion-capture laboratory), ...
  std::string frame = "patient";
  // Where the set comes from: "radiographs", "slicer_markups", "static_trial", ...
  std::string source;
  std::vector<Landmark> landmarks;  // in the order they were given

  // The landmark with this exact name, or nullptr.
  [[nodiscard]] const Landmark* find(std::string_view name) const;
  // Names in order.
  [[nodiscard]] std::vector<std::string> names() const;
};

// Throws InvalidInputError naming the landmark and field unless: the frame is
// non-empty, every name is non-empty and unique, and every position, pixel
// and reprojection error is finite (errors also >= 0) with non-empty view names.
void validate_landmark_set(const LandmarkSet& set);

// nlohmann hooks (found by argument-dependent lookup, so that
// `nlohmann::json j = set;` and `j.get<LandmarkSet>()` work). to_json
// validates first; from_json throws InvalidInputError like
// landmark_set_from_json_text with `what` = "landmark set".
void to_json(nlohmann::json& json, const LandmarkSet& set);
void from_json(const nlohmann::json& json, LandmarkSet& set);

// The canonical text (see the file comment), ending with a newline.
std::string landmark_set_to_json_text(const LandmarkSet& set);

// Parses and checks the canonical JSON. `what` names the text in messages (a
// file path, "node 'triangulate' output 'landmarks'", ...). Throws
// InvalidInputError "<what>: <where>: <problem>", e.g. "<what>: landmarks[2]
// ('patella_centre_r'): field 'position_mm' must be 3 finite numbers, got
// [1,2]". Unknown extra fields are ignored; a version other than 1 is
// rejected; NaN and Infinity are rejected (JSON has no such numbers).
LandmarkSet landmark_set_from_json(const nlohmann::json& json, std::string_view what);
LandmarkSet landmark_set_from_json_text(std::string_view text, std::string_view what);

}  // namespace mmm::landmarks

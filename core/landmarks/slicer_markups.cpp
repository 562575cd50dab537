#include "core/landmarks/slicer_markups.h"

#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <system_error>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/landmarks/landmark_labels.h"
#include "core/landmarks/message_text.h"

namespace mmm::landmarks {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

constexpr const char* kSchema =
    "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/"
    "Schema/markups-schema-v1.0.3.json#";

using detail::describe_json;

std::string read_text(const fs::path& file) {
  std::error_code error;
  if (!fs::exists(file, error)) throw IoError(file, "no such file");
  if (!fs::is_regular_file(file, error)) {
    throw IoError(file, "is not a regular file; expected a Slicer markups file (.mrk.json)");
  }
  const std::uintmax_t size = fs::file_size(file, error);
  if (error) throw IoError(file, "cannot read its size: " + error.message());
  return read_file_bytes(file, size);
}

// Reads one file; every failure is an IoError naming the file and JSON path.
class MarkupsReader {
 public:
  MarkupsReader(fs::path file, const MarkupsReadOptions& options)
      : file_(std::move(file)), options_(options) {}

  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throw IoError(file_, (where.empty() ? "" : where + ": ") + problem);
  }

  MarkupsReadResult read() {
    const std::string text = read_text(file_);
    Json root;
    try {
      root = parse_json(text);
    } catch (const Json::parse_error& error) {
      fail("", std::string("not valid JSON: ") + error.what());
    }
    if (!root.is_object()) fail("", "must hold a JSON object, got " + describe_json(root));
    const auto markups = root.find("markups");
    if (markups == root.end() || !markups->is_array()) {
      fail("", "field 'markups' must be an array; hint: is this a Slicer .mrk.json file?");
    }
    result_.landmarks.frame = "patient";
    result_.landmarks.source = "slicer_markups";
    bool any_point_list = false;
    for (std::size_t m = 0; m < markups->size(); ++m) {
      any_point_list =
          markup((*markups)[m], "markups[" + std::to_string(m) + "]") || any_point_list;
    }
    if (!any_point_list) {
      fail("",
           "holds no point list (markup of type \"Fiducial\"); hint: save the landmarks as "
           "a Point List in Slicer");
    }
    return std::move(result_);
  }

 private:
  // Reads markups[m]; false when it is not a point list.
  bool markup(const Json& entry, const std::string& where) {
    if (!entry.is_object()) fail(where, "must be a JSON object, got " + describe_json(entry));
    const auto type = entry.find("type");
    if (type == entry.end() || !type->is_string()) {
      fail(where, "field 'type' must be a string, e.g. \"Fiducial\"");
    }
    if (type->get<std::string>() != "Fiducial") {
      result_.notes.push_back(where + ": markup of type '" + type->get<std::string>() +
                              "' ignored (only point lists, type \"Fiducial\", hold landmarks)");
      return false;
    }
    // LPS: Slicer's default in files, and what Slicer 5 writes.
    std::string system = "LPS";
    if (const auto it = entry.find("coordinateSystem"); it != entry.end()) {
      if (!it->is_string() || (*it != "LPS" && *it != "RAS")) {
        fail(where + ".coordinateSystem", R"(must be "LPS" or "RAS", got )" + describe_json(*it));
      }
      system = it->get<std::string>();
    }
    result_.coordinate_system = system;
    double scale = 1.0;  // to mm
    if (const auto it = entry.find("coordinateUnits"); it != entry.end()) {
      const std::string units = it->is_string() ? it->get<std::string>() : "";
      if (units == "mm") {
        scale = 1.0;
      } else if (units == "um") {
        scale = 1e-3;
      } else if (units == "m") {
        scale = 1e3;
      } else {
        fail(where + ".coordinateUnits", R"(must be "mm", "um" or "m", got )" + describe_json(*it));
      }
    }
    const auto points = entry.find("controlPoints");
    if (points == entry.end()) {
      result_.notes.push_back(where + ": point list without control points");
      return true;
    }
    if (!points->is_array()) {
      fail(where + ".controlPoints", "must be an array, got " + describe_json(*points));
    }
    for (std::size_t p = 0; p < points->size(); ++p) {
      control_point((*points)[p], where + ".controlPoints[" + std::to_string(p) + "]",
                    system == "LPS", scale);
    }
    return true;
  }

  void control_point(const Json& point, const std::string& where, bool lps, double scale) {
    if (!point.is_object()) fail(where, "must be a JSON object, got " + describe_json(point));
    std::string label;
    if (const auto it = point.find("label"); it != point.end()) {
      if (!it->is_string()) fail(where + ".label", "must be a string, got " + describe_json(*it));
      label = it->get<std::string>();
    }
    if (const auto it = point.find("positionStatus"); it != point.end()) {
      if (!it->is_string()) {
        fail(where + ".positionStatus", "must be a string, got " + describe_json(*it));
      }
      const std::string status = it->get<std::string>();
      if (status != "defined") {
        result_.notes.push_back(where + " ('" + label + "'): skipped, its position is " + status +
                                " (not placed)");
        return;
      }
    }
    if (label.empty()) {
      result_.notes.push_back(where + ": skipped, the point has no label");
      return;
    }
    const auto position = point.find("position");
    const auto bad_position = [&] {
      fail(where + ".position",
           "must be 3 finite numbers, got " +
               (position == point.end() ? "nothing" : describe_json(*position)));
    };
    if (position == point.end() || !position->is_array() || position->size() != 3) bad_position();
    Eigen::Vector3d xyz;
    for (int i = 0; i < 3; ++i) {
      const Json& value = (*position)[static_cast<std::size_t>(i)];
      if (!value.is_number() || !std::isfinite(value.get<double>())) bad_position();
      xyz(i) = value.get<double>() * scale;
    }
    if (lps) {
      xyz.x() = -xyz.x();
      xyz.y() = -xyz.y();
    }
    std::string name = match_landmark_name(label, options_);
    if (name.empty()) {
      fail(where + ".label", "'" + label +
                                 "' names no landmark mmm knows; hint: rename the point in "
                                 "Slicer to an atlas name or one of its labels (case, spaces "
                                 "and '_' do not matter):\n" +
                                 landmark_label_table_text());
    }
    if (name != label) {
      result_.notes.push_back(where + ": label '" + label + "' read as '" + name + "'");
    }
    if (const auto [it, inserted] = first_path_.emplace(name, where); !inserted) {
      fail(where, "label '" + label + "' gives landmark '" + name + "', already given by " +
                      it->second + "; hint: delete or rename one of the two points");
    }
    Landmark landmark;
    landmark.name = name;
    landmark.position_mm = xyz;
    result_.landmarks.landmarks.push_back(std::move(landmark));
  }

  fs::path file_;
  const MarkupsReadOptions& options_;
  MarkupsReadResult result_;
  std::map<std::string, std::string> first_path_;  // landmark name -> JSON path
};

}  // namespace

std::string match_landmark_name(std::string_view label, const MarkupsReadOptions& options) {
  if (find_landmark_labels(label) != nullptr) return std::string(label);
  if (std::string name = landmark_for_label(label); !name.empty()) return name;
  const auto it = options.aliases.find(normalise_label(label));
  return it == options.aliases.end() ? std::string() : it->second;
}

MarkupsReadResult read_slicer_markups(const fs::path& file, const MarkupsReadOptions& options) {
  return MarkupsReader(file, options).read();
}

void write_slicer_markups(const LandmarkSet& set, const fs::path& file,
                          const MarkupsWriteOptions& options) {
  if (options.coordinate_system != "LPS" && options.coordinate_system != "RAS") {
    throw InvalidInputError(
        R"(MarkupsWriteOptions.coordinate_system must be "LPS" or "RAS", got ")" +
        options.coordinate_system + "\"");
  }
  validate_landmark_set(set);
  const bool lps = options.coordinate_system == "LPS";
  Json points = Json::array();
  for (std::size_t i = 0; i < set.landmarks.size(); ++i) {
    const Landmark& landmark = set.landmarks[i];
    Eigen::Vector3d xyz = landmark.position_mm;
    if (lps) {
      xyz.x() = -xyz.x();
      xyz.y() = -xyz.y();
    }
    Json point;
    point["id"] = std::to_string(i + 1);
    point["label"] = landmark.name;
    point["description"] = "";
    point["position"] = {xyz.x(), xyz.y(), xyz.z()};
    // Identity orientation, written in the file's coordinate system.
    point["orientation"] = lps ? Json{-1.0, -0.0, -0.0, -0.0, -1.0, -0.0, 0.0, 0.0, 1.0}
                               : Json{1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
    point["selected"] = true;
    point["locked"] = false;
    point["visibility"] = true;
    point["positionStatus"] = "defined";
    points.push_back(std::move(point));
  }
  Json markup;
  markup["type"] = "Fiducial";
  markup["coordinateSystem"] = options.coordinate_system;
  markup["coordinateUnits"] = "mm";
  markup["locked"] = false;
  markup["labelFormat"] = "%N-%d";
  markup["controlPoints"] = std::move(points);
  Json root;
  root["@schema"] = kSchema;
  root["markups"] = Json::array({std::move(markup)});
  write_file_atomically(file, root.dump(4) + "\n", "a Slicer markups file");
}

}  // namespace mmm::landmarks

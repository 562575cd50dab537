#include "core/motion/motion_io.h"

#include <cmath>

#include "core/errors.h"

namespace mmm::motion {
namespace {

constexpr const char* kMotionFormat = "mmm-motion 1";

nlohmann::json pose_json(const Eigen::Isometry3d& pose) {
  nlohmann::json row = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) row.push_back(pose.linear()(r, c));
    row.push_back(pose.translation()(r));
  }
  return row;
}

[[noreturn]] void fail(std::string_view what, const std::string& problem) {
  throw InvalidInputError(std::string(what) + ": " + problem);
}

const nlohmann::json& field(const nlohmann::json& object, const char* key, std::string_view what,
                            const std::string& path) {
  if (!object.is_object() || !object.contains(key)) fail(what, path + key + " is missing");
  return object.at(key);
}

double number(const nlohmann::json& value, std::string_view what, const std::string& path) {
  if (!value.is_number()) fail(what, path + " is not a number");
  const double x = value.get<double>();
  if (!std::isfinite(x)) fail(what, path + " is not finite");
  return x;
}

std::vector<std::string> names(const nlohmann::json& value, std::string_view what,
                               const std::string& path) {
  if (!value.is_array()) fail(what, path + " is not a list of names");
  std::vector<std::string> result;
  for (const nlohmann::json& name : value) {
    if (!name.is_string()) fail(what, path + " holds a non-string");
    result.push_back(name.get<std::string>());
  }
  return result;
}

}  // namespace

nlohmann::json motion_to_json(const FusedMotion& motion, const std::string& model,
                              const std::string& model_kind) {
  nlohmann::json json;
  json["format"] = kMotionFormat;
  json["model"] = model;
  json["model_kind"] = model_kind;
  json["frame"] = model_kind == "atlas"
                      ? "poses map the atlas's rest-pose frame (mm) to the trial's lab (mm)"
                      : "poses map each OpenSim body frame (mm) to the trial's lab (mm)";
  json["times"] =
      std::vector<double>(motion.times.data(), motion.times.data() + motion.times.size());
  json["trial_frames"] = motion.trial_frames;
  nlohmann::json units = nlohmann::json::array();
  for (const CoordinateUnit unit : motion.coordinate_units) {
    units.push_back(unit == CoordinateUnit::kAngle ? "rad" : "mm");
  }
  nlohmann::json values = nlohmann::json::array();
  for (Eigen::Index k = 0; k < motion.coordinates.rows(); ++k) {
    const Eigen::VectorXd row = motion.coordinates.row(k).transpose();
    values.push_back(std::vector<double>(row.data(), row.data() + row.size()));
  }
  json["coordinates"] = {{"names", motion.coordinate_names}, {"units", units}, {"values", values}};
  nlohmann::json poses = nlohmann::json::array();
  for (const std::vector<Eigen::Isometry3d>& frame : motion.poses) {
    nlohmann::json bodies = nlohmann::json::array();
    for (const Eigen::Isometry3d& pose : frame) bodies.push_back(pose_json(pose));
    poses.push_back(bodies);
  }
  json["bodies"] = {{"names", motion.body_names}, {"poses", poses}};
  nlohmann::json errors = nlohmann::json::array();
  for (Eigen::Index k = 0; k < motion.marker_errors.rows(); ++k) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index m = 0; m < motion.marker_errors.cols(); ++m) {
      const double e = motion.marker_errors(k, m);
      row.push_back(std::isfinite(e) ? nlohmann::json(e) : nlohmann::json(nullptr));
    }
    errors.push_back(row);
  }
  json["markers"] = {{"names", motion.marker_names}, {"errors_mm", errors}};
  return json;
}

FusedMotion motion_from_json(const nlohmann::json& json, std::string_view what) {
  if (!json.is_object() || json.value("format", "") != kMotionFormat) {
    fail(what,
         R"(not a fused motion (expected "format": ")" + std::string(kMotionFormat) + R"("))");
  }
  FusedMotion motion;
  const nlohmann::json& times = field(json, "times", what, "");
  if (!times.is_array() || times.empty()) fail(what, "times is not a non-empty list");
  const auto frames = static_cast<Eigen::Index>(times.size());
  motion.times.resize(frames);
  for (Eigen::Index k = 0; k < frames; ++k) {
    motion.times(k) =
        number(times[static_cast<std::size_t>(k)], what, "times[" + std::to_string(k) + "]");
  }
  const nlohmann::json& trial_frames = field(json, "trial_frames", what, "");
  if (!trial_frames.is_array() || static_cast<Eigen::Index>(trial_frames.size()) != frames) {
    fail(what, "trial_frames does not have one entry per time");
  }
  for (const nlohmann::json& f : trial_frames) motion.trial_frames.push_back(f.get<int>());
  const nlohmann::json& coordinates = field(json, "coordinates", what, "");
  motion.coordinate_names =
      names(field(coordinates, "names", what, "coordinates."), what, "coordinates.names");
  const std::vector<std::string> units =
      names(field(coordinates, "units", what, "coordinates."), what, "coordinates.units");
  if (units.size() != motion.coordinate_names.size()) {
    fail(what, "coordinates.units does not have one unit per name");
  }
  for (const std::string& unit : units) {
    if (unit != "rad" && unit != "mm") fail(what, "coordinates.units: '" + unit + "' (rad or mm)");
    motion.coordinate_units.push_back(unit == "rad" ? CoordinateUnit::kAngle
                                                    : CoordinateUnit::kLength);
  }
  const nlohmann::json& values = field(coordinates, "values", what, "coordinates.");
  const auto n = static_cast<Eigen::Index>(motion.coordinate_names.size());
  if (!values.is_array() || static_cast<Eigen::Index>(values.size()) != frames) {
    fail(what, "coordinates.values does not have one row per time");
  }
  motion.coordinates.resize(frames, n);
  for (Eigen::Index k = 0; k < frames; ++k) {
    const nlohmann::json& row = values[static_cast<std::size_t>(k)];
    if (!row.is_array() || static_cast<Eigen::Index>(row.size()) != n) {
      fail(what, "coordinates.values[" + std::to_string(k) + "] does not have one value per name");
    }
    for (Eigen::Index c = 0; c < n; ++c) {
      motion.coordinates(k, c) = number(row[static_cast<std::size_t>(c)], what,
                                        "coordinates.values[" + std::to_string(k) + "]");
    }
  }
  const nlohmann::json& bodies = field(json, "bodies", what, "");
  motion.body_names = names(field(bodies, "names", what, "bodies."), what, "bodies.names");
  const nlohmann::json& poses = field(bodies, "poses", what, "bodies.");
  if (!poses.is_array() || static_cast<Eigen::Index>(poses.size()) != frames) {
    fail(what, "bodies.poses does not have one entry per time");
  }
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const nlohmann::json& frame = poses[k];
    if (!frame.is_array() || frame.size() != motion.body_names.size()) {
      fail(what, "bodies.poses[" + std::to_string(k) + "] does not have one pose per body");
    }
    std::vector<Eigen::Isometry3d> placed;
    for (const nlohmann::json& pose : frame) {
      if (!pose.is_array() || pose.size() != 12) {
        fail(what, "bodies.poses[" + std::to_string(k) + "]: a pose needs 12 numbers");
      }
      Eigen::Matrix<double, 3, 4> m;
      for (int i = 0; i < 12; ++i) {
        m(i / 4, i % 4) = number(pose[static_cast<std::size_t>(i)], what,
                                 "bodies.poses[" + std::to_string(k) + "]");
      }
      Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
      iso.linear() = m.leftCols<3>();
      iso.translation() = m.col(3);
      placed.push_back(iso);
    }
    motion.poses.push_back(std::move(placed));
  }
  if (json.contains("markers")) {
    const nlohmann::json& markers = json.at("markers");
    motion.marker_names = names(field(markers, "names", what, "markers."), what, "markers.names");
    const nlohmann::json& errors = field(markers, "errors_mm", what, "markers.");
    const auto count = static_cast<Eigen::Index>(motion.marker_names.size());
    motion.marker_errors = Eigen::MatrixXd::Constant(frames, count, std::nan(""));
    if (!errors.is_array() || static_cast<Eigen::Index>(errors.size()) != frames) {
      fail(what, "markers.errors_mm does not have one row per time");
    }
    for (Eigen::Index k = 0; k < frames; ++k) {
      const nlohmann::json& row = errors[static_cast<std::size_t>(k)];
      if (!row.is_array() || static_cast<Eigen::Index>(row.size()) != count) {
        fail(what, "markers.errors_mm[" + std::to_string(k) + "] does not have one per marker");
      }
      for (Eigen::Index m = 0; m < count; ++m) {
        const nlohmann::json& e = row[static_cast<std::size_t>(m)];
        if (!e.is_null()) motion.marker_errors(k, m) = e.get<double>();
      }
    }
  }
  return motion;
}

}  // namespace mmm::motion

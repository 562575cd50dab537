#include "core/image/calibration_object.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/bounded_json.h"
#include "core/errors.h"

namespace mmm::image {
namespace {

constexpr std::size_t kMaxBytes = std::size_t{1} << 20U;

nlohmann::json root_of(std::string_view text, const std::filesystem::path& source,
                       const char* format) {
  if (text.size() > kMaxBytes) {
    throw IoError(source, "is " + std::to_string(text.size()) + " bytes; at most 1 MiB");
  }
  nlohmann::json root;
  try {
    root = parse_json(text);
  } catch (const std::exception& error) {
    throw IoError(source, std::string("is not valid JSON: ") + error.what());
  }
  if (!root.is_object() || root.value("format", "") != format) {
    throw IoError(source, std::string("field 'format' must be \"") + format + "\"");
  }
  if (!root.contains("version") || root["version"] != 1) {
    throw IoError(source, "field 'version' must be 1");
  }
  return root;
}

// A JSON array of `size` finite numbers.
template <int N>
Eigen::Matrix<double, N, 1> numbers(const nlohmann::json& value,
                                    const std::filesystem::path& source, const std::string& where) {
  if (!value.is_array() || value.size() != N) {
    throw IoError(source, where + ": must be an array of " + std::to_string(N) + " numbers");
  }
  Eigen::Matrix<double, N, 1> out;
  for (int k = 0; k < N; ++k) {
    const nlohmann::json& x = value[static_cast<std::size_t>(k)];
    if (!x.is_number() || !std::isfinite(x.get<double>())) {
      throw IoError(source, where + "[" + std::to_string(k) + "]: must be a finite number");
    }
    out(k) = x.get<double>();
  }
  return out;
}

}  // namespace

CalibrationObject parse_calibration_object(std::string_view text,
                                           const std::filesystem::path& source) {
  const nlohmann::json root = root_of(text, source, "mmm-calibration-object");
  CalibrationObject object;
  object.name = root.value("name", "");
  if (!root.contains("beads") || !root["beads"].is_object() || root["beads"].empty()) {
    throw IoError(source, "field 'beads' must be an object of bead name -> [x, y, z] (mm)");
  }
  for (const auto& [name, position] : root["beads"].items()) {
    object.beads[name] = numbers<3>(position, source, "beads." + name);
  }
  return object;
}

BeadClicks parse_bead_clicks(std::string_view text, const std::filesystem::path& source,
                             const CalibrationObject& object) {
  const nlohmann::json root = root_of(text, source, "mmm-bead-clicks");
  if (!root.contains("views") || !root["views"].is_object() || root["views"].empty()) {
    throw IoError(source, "field 'views' must be an object of view name -> {bead: [u, v]}");
  }
  BeadClicks clicks;
  for (const auto& [view, beads] : root["views"].items()) {
    if (!beads.is_object()) {
      throw IoError(source, "views." + view + ": must be an object of bead name -> [u, v]");
    }
    for (const auto& [bead, pixel] : beads.items()) {
      std::string where = "views.";
      where += view;
      where += '.';
      where += bead;
      if (!object.beads.contains(bead)) {
        throw IoError(source, where + ": unknown bead (the object has " +
                                  std::to_string(object.beads.size()) + " beads, " +
                                  object.beads.begin()->first + " to " +
                                  object.beads.rbegin()->first + ")");
      }
      clicks[view][bead] = numbers<2>(pixel, source, where);
    }
  }
  return clicks;
}

}  // namespace mmm::image

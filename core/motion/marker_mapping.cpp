#include "core/motion/marker_mapping.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <sstream>

#include "core/bounded_yaml.h"
#include "core/errors.h"
#include "core/suggest.h"

namespace mmm::motion {
namespace {

constexpr double kMarkerMappingFormat = 1;

class MarkerMappingReader {
 public:
  explicit MarkerMappingReader(std::filesystem::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& field,
                         const std::string& problem) const {
    std::ostringstream message;
    if (node.IsDefined() && node.Mark().line >= 0) {
      message << "line " << node.Mark().line + 1 << ":" << node.Mark().column + 1 << ": ";
    }
    message << field << ": " << problem;
    throw IoError(file_, message.str());
  }

  void check_keys(const YAML::Node& map, const std::string& field,
                  const std::vector<std::string>& allowed) const {
    if (!map.IsMap()) fail(map, field, "expects a mapping");
    for (const auto& entry : map) {
      const auto key = entry.first.as<std::string>();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string problem = "unknown key";
        problem += did_you_mean(key, allowed);
        problem += " (allowed: ";
        problem += join_names(allowed);
        problem += ")";
        std::string where = field;
        where += ".";
        where += key;
        fail(entry.first, where, problem);
      }
    }
  }

  [[nodiscard]] std::string text(const YAML::Node& map, const std::string& key,
                                 const std::string& field, bool needed) const {
    const YAML::Node value = map[key];
    if (!value.IsDefined() || value.IsNull()) {
      if (needed) fail(map, field + "." + key, "is required");
      return {};
    }
    if (!value.IsScalar() || value.Scalar().empty()) {
      fail(value, field + "." + key, "expects a non-empty name");
    }
    return value.Scalar();
  }

  [[nodiscard]] double number(const YAML::Node& map, const std::string& key,
                              const std::string& field, double fallback, double low) const {
    const YAML::Node value = map[key];
    if (!value.IsDefined() || value.IsNull()) return fallback;
    double result = 0;
    if (!value.IsScalar() || !YAML::convert<double>::decode(value, result) ||
        !std::isfinite(result)) {
      fail(value, field + "." + key, "expects a finite number, got '" + value.Scalar() + "'");
    }
    if (result < low) {
      std::ostringstream range;
      range << "is " << result << ", expected >= " << low;
      fail(value, field + "." + key, range.str());
    }
    return result;
  }

 private:
  std::filesystem::path file_;
};

MarkerMapping parse_root(const YAML::Node& root, const std::filesystem::path& file) {
  const MarkerMappingReader reader(file);
  if (!root.IsMap()) reader.fail(root, "(top)", "expects a mapping holding mmm_marker_mapping: 1");
  reader.check_keys(root, "(top)",
                    {"mmm_marker_mapping", "name", "description", "markers", "coordinates"});
  if (reader.number(root, "mmm_marker_mapping", "(top)", -1, -1e9) != kMarkerMappingFormat) {
    reader.fail(root, "mmm_marker_mapping",
                "must be 1 (this file is not an mmm marker mapping, or a newer one)");
  }
  MarkerMapping mapping;
  mapping.source = file;
  mapping.name = reader.text(root, "name", "(top)", false);
  mapping.description = reader.text(root, "description", "(top)", false);
  const YAML::Node markers = root["markers"];
  if (!markers.IsDefined() || !markers.IsSequence() || markers.size() == 0) {
    reader.fail(root, "markers", "expects a non-empty list of {trial, model, weight}");
  }
  std::set<std::string> trial_names;
  std::set<std::string> model_names;
  bool any_weight = false;
  for (std::size_t i = 0; i < markers.size(); ++i) {
    const YAML::Node entry = markers[i];
    const std::string field = "markers[" + std::to_string(i) + "]";
    reader.check_keys(entry, field, {"trial", "model", "weight"});
    MarkerTask task;
    task.trial = reader.text(entry, "trial", field, true);
    task.model = reader.text(entry, "model", field, false);
    if (task.model.empty()) task.model = task.trial;
    task.weight = reader.number(entry, "weight", field, 1.0, 0.0);
    if (!trial_names.insert(task.trial).second) {
      reader.fail(entry, field + ".trial", "'" + task.trial + "' is mapped twice");
    }
    if (!model_names.insert(task.model).second) {
      reader.fail(entry, field + ".model",
                  "model marker '" + task.model + "' is driven by two trial markers");
    }
    any_weight = any_weight || task.weight > 0;
    mapping.markers.push_back(std::move(task));
  }
  if (!any_weight) reader.fail(markers, "markers", "every weight is 0: nothing would be tracked");
  const YAML::Node coordinates = root["coordinates"];
  if (coordinates.IsDefined() && !coordinates.IsNull()) {
    if (!coordinates.IsSequence()) {
      reader.fail(coordinates, "coordinates", "expects a list of {name, value, weight}");
    }
    std::set<std::string> names;
    for (std::size_t i = 0; i < coordinates.size(); ++i) {
      const YAML::Node entry = coordinates[i];
      const std::string field = "coordinates[" + std::to_string(i) + "]";
      reader.check_keys(entry, field, {"name", "value", "weight"});
      CoordinateTask task;
      task.coordinate = reader.text(entry, "name", field, true);
      task.value = reader.number(entry, "value", field, 0.0, -1e300);
      task.weight = reader.number(entry, "weight", field, 1.0, 0.0);
      if (!names.insert(task.coordinate).second) {
        reader.fail(entry, field + ".name", "'" + task.coordinate + "' has two tasks");
      }
      mapping.coordinates.push_back(std::move(task));
    }
  }
  return mapping;
}

}  // namespace

MarkerMapping parse_marker_mapping(std::string_view text,
                                   const std::filesystem::path& name_for_messages) {
  YAML::Node root;
  try {
    root = load_yaml(text);
  } catch (const YAML::Exception& error) {
    throw IoError(name_for_messages,
                  "line " + std::to_string(error.mark.line + 1) + ": malformed YAML: " + error.msg);
  }
  return parse_root(root, name_for_messages);
}

MarkerMapping read_marker_mapping(const std::filesystem::path& file) {
  YAML::Node root;
  try {
    root = load_yaml_file(file);
  } catch (const YAML::BadFile&) {
    throw IoError(file, "cannot open the marker mapping (check the path)");
  } catch (const YAML::Exception& error) {
    throw IoError(file,
                  "line " + std::to_string(error.mark.line + 1) + ": malformed YAML: " + error.msg);
  }
  return parse_root(root, file);
}

std::string_view gait2392_marker_mapping_text() {
  static constexpr std::string_view kText =
#include "core/motion/gait2392_marker_mapping.inc"
      ;
  return kText;
}

MarkerMapping gait2392_marker_mapping() {
  return parse_marker_mapping(gait2392_marker_mapping_text(), "gait2392_marker_mapping.yaml");
}

}  // namespace mmm::motion

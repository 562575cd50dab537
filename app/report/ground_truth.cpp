#include "app/report/ground_truth.h"

#include <Eigen/Core>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "app/report/html.h"
#include "app/report/json_file.h"
#include "core/atlas/atlas_surface_errors.h"
#include "core/errors.h"
#include "core/xml_escape.h"

namespace mmm::app::report {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A file of the patient folder; a clear error when it is not a patient's.
json read_patient_json(const fs::path& file) {
  std::optional<json> parsed =
      read_json_if_present(file, "make the patient again (mmm patient synth)");
  if (!parsed) {
    throw InvalidInputError(file.string() +
                            ": missing; --truth takes a folder written by mmm patient synth");
  }
  return std::move(*parsed);
}

Eigen::Vector3d point(const json& value, const std::string& where) {
  if (!value.is_array() || value.size() != 3) {
    throw InvalidInputError(where + ": expected [x, y, z] in mm");
  }
  return {value[0].get<double>(), value[1].get<double>(), value[2].get<double>()};
}

}  // namespace

std::string truth_landmarks_html(const json& landmarks, const fs::path& landmarks_file,
                                 const fs::path& patient) {
  const fs::path truth_file = patient / "ground_truth.json";
  const json truth = read_patient_json(truth_file);
  const json true_landmarks = truth.value("landmarks", json::object());
  std::vector<std::vector<std::string>> rows;
  for (const json& landmark : landmarks.value("landmarks", json::array())) {
    const std::string name = landmark.value("name", "");
    if (!true_landmarks.contains(name)) {
      throw InvalidInputError(truth_file.string() + ": no landmark '" + name +
                              "' (is this the study's patient?)");
    }
    const Eigen::Vector3d placed =
        point(landmark.value("position_mm", json()), landmarks_file.string() + ": " + name);
    const Eigen::Vector3d real =
        point(true_landmarks[name].value("position_mm", json()), truth_file.string() + ": " + name);
    rows.push_back({name, fixed((placed - real).norm(), 2)});
  }
  return "<p>The accepted landmarks against the synthetic patient's true ones (" +
         xml_escaped(patient.filename().string()) + "):</p>\n" +
         html_table({"landmark", "distance from the truth (mm)"}, rows);
}

std::string truth_surfaces_html(const fs::path& outputs, const fs::path& patient, int threads) {
  const fs::path scaled = outputs / "patient_atlas";
  if (!fs::exists(scaled / "atlas.yaml")) return {};
  if (!fs::exists(patient / "atlas" / "atlas.yaml")) {
    throw InvalidInputError((patient / "atlas").string() +
                            ": no atlas.yaml; --truth takes a folder written by mmm patient synth");
  }
  std::string html;
  const std::vector<atlas::ElementSurfaceError> errors =
      atlas::atlas_surface_errors(scaled, patient / "atlas", "full", threads);
  std::vector<std::vector<std::string>> rows;
  std::vector<double> bone_means;
  std::vector<double> muscle_means;
  for (const atlas::ElementSurfaceError& e : errors) {
    rows.push_back({e.element, e.kind, fixed(e.distance.mean_mm, 2), fixed(e.distance.p95_mm, 2),
                    fixed(e.distance.max_mm, 2)});
    (e.kind == "bone" ? bone_means : muscle_means).push_back(e.distance.mean_mm);
  }
  const auto median = [](std::vector<double> values) {
    if (values.empty()) return 0.0;
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
  };
  html +=
      "<p>Surface distance of every scaled bone and muscle (at rest) to the synthetic patient's "
      "own (" +
      xml_escaped(patient.filename().string()) +
      "), symmetric and area-weighted: median of the means " + fixed(median(bone_means), 2) +
      " mm over the bones, " + fixed(median(muscle_means), 2) + " mm over the muscles.</p>\n";
  html += html_table({"element", "kind", "mean (mm)", "95th percentile (mm)", "max (mm)"}, rows);
  return html;
}

}  // namespace mmm::app::report

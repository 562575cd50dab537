#include "nodes/landmark_report.h"

#include <algorithm>
#include <array>
#include <nlohmann/json.hpp>
#include <string>

#include "core/landmarks/landmark_set.h"

namespace mmm::nodes {

workflow::NodeSpec LandmarkReport::spec() {
  using workflow::port::LandmarkSet;
  using workflow::port::Report;
  return workflow::NodeSpec{"landmark_report", 1,
                            "Positions, distances along the leg and reprojection errors of a "
                            "landmark set"}
      .input<LandmarkSet>("landmarks", "The landmarks (e.g. from the landmark station)")
      .output<Report>("report", "JSON report");
}

void LandmarkReport::run(workflow::NodeContext& context) {
  const landmarks::LandmarkSet set = landmarks::landmark_set_from_json_text(
      context.input_bytes("landmarks"), context.input("landmarks").path.string());
  nlohmann::json report;
  report["frame"] = set.frame;
  report["source"] = set.source;
  nlohmann::json positions = nlohmann::json::object();
  for (const landmarks::Landmark& landmark : set.landmarks) {
    positions[landmark.name] = {landmark.position_mm.x(), landmark.position_mm.y(),
                                landmark.position_mm.z()};
  }
  report["landmarks"] = positions;
  nlohmann::json distances = nlohmann::json::object();
  for (const char* side : {"_r", "_l"}) {
    const std::array<std::string, 3> chain = {std::string("femoral_head_centre") + side,
                                              std::string("patella_centre") + side,
                                              std::string("ankle_centre") + side};
    for (int i = 0; i + 1 < 3; ++i) {
      const landmarks::Landmark* a = set.find(chain[i]);
      const landmarks::Landmark* b = set.find(chain[i + 1]);
      if (a == nullptr || b == nullptr) continue;
      const double d = (a->position_mm - b->position_mm).norm();
      distances[chain[i] + "-" + chain[i + 1]] = d;
      context.info(chain[i] + " - " + chain[i + 1] + ": " + std::to_string(d) + " mm");
    }
  }
  report["distances_mm"] = distances;
  double largest = 0;
  double sum = 0;
  int count = 0;
  for (const landmarks::Landmark& landmark : set.landmarks) {
    for (const auto& [view, error] : landmark.reprojection_error_mm) {
      largest = std::max(largest, error);
      sum += error;
      ++count;
    }
  }
  if (count > 0) report["reprojection_error_mm"] = {{"max", largest}, {"mean", sum / count}};
  context.set_output("report", report.dump(2) + "\n");
}

}  // namespace mmm::nodes

#include "core/landmarks/static_trial_landmarks.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>

#include "core/errors.h"
#include "core/suggest.h"

namespace mmm::landmarks {

namespace {

// Harrington et al. 2007 (J Biomech 40:595-602), regression on pelvis width
// PW and depth PD (mm), ISB pelvis frame.
constexpr double kAnteriorPerDepth = -0.24;
constexpr double kAnteriorOffsetMm = -9.9;
constexpr double kSuperiorPerWidth = -0.30;
constexpr double kSuperiorOffsetMm = -10.9;
constexpr double kLateralPerWidth = 0.33;
constexpr double kLateralOffsetMm = 7.3;

// Positions (mm) of the markers of one landmark in one frame -> the landmark.
using Rule = std::function<Eigen::Vector3d(const std::vector<Eigen::Vector3d>&)>;

struct Recipe {
  std::string name;
  std::vector<Eigen::Index> markers;
  Rule rule;
};

Eigen::Vector3d midpoint(const std::vector<Eigen::Vector3d>& p) { return 0.5 * (p[0] + p[1]); }

// Posterior point from markers[2..]: the sacral marker or the PSIS midpoint.
Eigen::Vector3d posterior_point(const std::vector<Eigen::Vector3d>& p) {
  return p.size() == 3 ? p[2] : Eigen::Vector3d(0.5 * (p[2] + p[3]));
}

}  // namespace

HarringtonHipCentres harrington_hip_centres(const Eigen::Vector3d& asis_r,
                                            const Eigen::Vector3d& asis_l,
                                            const Eigen::Vector3d& posterior) {
  if (!asis_r.allFinite() || !asis_l.allFinite() || !posterior.allFinite()) {
    throw InvalidInputError("harrington_hip_centres: marker positions must be finite");
  }
  const Eigen::Vector3d origin = 0.5 * (asis_r + asis_l);
  const Eigen::Vector3d across = asis_r - asis_l;
  HarringtonHipCentres hips;
  hips.pelvis_width_mm = across.norm();
  if (!(hips.pelvis_width_mm > 0)) {
    throw InvalidInputError("harrington_hip_centres: the two ASIS markers coincide");
  }
  const Eigen::Vector3d z = across / hips.pelvis_width_mm;
  const Eigen::Vector3d back_to_front = origin - posterior;
  hips.pelvis_depth_mm = back_to_front.norm();
  const Eigen::Vector3d forward = back_to_front - back_to_front.dot(z) * z;
  // 1e-6 of the pelvis width: rounding, not a pelvis.
  if (!(forward.norm() > 1e-6 * hips.pelvis_width_mm)) {
    throw InvalidInputError(
        "harrington_hip_centres: the posterior pelvis marker lies on the line through the ASIS "
        "markers; no anterior direction");
  }
  const Eigen::Vector3d x = forward.normalized();
  const Eigen::Vector3d y = z.cross(x);
  const double anterior = kAnteriorPerDepth * hips.pelvis_depth_mm + kAnteriorOffsetMm;
  const double superior = kSuperiorPerWidth * hips.pelvis_width_mm + kSuperiorOffsetMm;
  const double lateral = kLateralPerWidth * hips.pelvis_width_mm + kLateralOffsetMm;
  hips.right = origin + anterior * x + superior * y + lateral * z;
  hips.left = origin + anterior * x + superior * y - lateral * z;
  return hips;
}

StaticTrialResult landmarks_from_static_trial(const opensim::MarkerTrajectories& trial,
                                              const StaticTrialOptions& options) {
  const std::string file = trial.source.string();
  const StaticTrialMarkers& names = options.markers;
  if (options.legs != "right" && options.legs != "left" && options.legs != "both") {
    throw InvalidInputError(R"(StaticTrialOptions.legs must be "right", "left" or "both", got ")" +
                            options.legs + "\"");
  }
  if (options.min_valid_frames < 1) {
    throw InvalidInputError("StaticTrialOptions.min_valid_frames must be >= 1, got " +
                            std::to_string(options.min_valid_frames));
  }
  if (names.posterior.empty() || names.posterior.size() > 2) {
    throw InvalidInputError(
        "StaticTrialMarkers.posterior must name one sacral marker or the two PSIS markers, got " +
        std::to_string(names.posterior.size()) + " names");
  }
  const auto index = [&](const std::string& marker) {
    const std::optional<Eigen::Index> found = trial.marker_index(marker);
    if (!found) {
      throw InvalidInputError(file + ": marker '" + marker + "' is not in the trial" +
                              did_you_mean(marker, trial.marker_names) +
                              "; hint: map the trial's marker names in StaticTrialMarkers");
    }
    return *found;
  };

  std::vector<Recipe> recipes;
  std::vector<Eigen::Index> pelvis = {index(names.asis_r), index(names.asis_l)};
  for (const std::string& marker : names.posterior) pelvis.push_back(index(marker));
  const bool right = options.legs != "left";
  const bool left = options.legs != "right";
  if (right) {
    recipes.push_back({"femoral_head_centre_r", pelvis, [](const auto& p) {
                         return harrington_hip_centres(p[0], p[1], posterior_point(p)).right;
                       }});
  }
  if (left) {
    recipes.push_back({"femoral_head_centre_l", pelvis, [](const auto& p) {
                         return harrington_hip_centres(p[0], p[1], posterior_point(p)).left;
                       }});
  }
  if (right) {
    recipes.push_back(
        {"knee_centre_r", {index(names.knee_lateral_r), index(names.knee_medial_r)}, midpoint});
  }
  if (left) {
    recipes.push_back(
        {"knee_centre_l", {index(names.knee_lateral_l), index(names.knee_medial_l)}, midpoint});
  }
  if (right) {
    recipes.push_back(
        {"ankle_centre_r", {index(names.ankle_lateral_r), index(names.ankle_medial_r)}, midpoint});
  }
  if (left) {
    recipes.push_back(
        {"ankle_centre_l", {index(names.ankle_lateral_l), index(names.ankle_medial_l)}, midpoint});
  }
  const auto first = [](const auto& p) { return p[0]; };
  recipes.push_back({"asis_r", {pelvis[0]}, first});
  recipes.push_back({"asis_l", {pelvis[1]}, first});

  StaticTrialResult result;
  result.landmarks.frame = "lab";
  result.landmarks.source = "static_trial";
  const double to_mm = trial.unit_to_mm;
  for (const Recipe& recipe : recipes) {
    std::vector<Eigen::Vector3d> per_frame;
    std::vector<Eigen::Vector3d> positions(recipe.markers.size());
    for (Eigen::Index f = 0; f < trial.num_frames(); ++f) {
      bool complete = true;
      for (std::size_t k = 0; k < recipe.markers.size() && complete; ++k) {
        positions[k] = trial.position(f, recipe.markers[k]) * to_mm;
        complete = positions[k].allFinite();
      }
      if (complete) per_frame.push_back(recipe.rule(positions));
    }
    if (std::ssize(per_frame) < options.min_valid_frames) {
      throw InvalidInputError(file + ": landmark '" + recipe.name + "' has all its markers in " +
                              std::to_string(per_frame.size()) + " of " +
                              std::to_string(trial.num_frames()) + " frames, fewer than " +
                              std::to_string(options.min_valid_frames) +
                              "; hint: fill the gaps or lower StaticTrialOptions.min_valid_frames");
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : per_frame) mean += p;
    mean /= static_cast<double>(per_frame.size());
    double sum_squares = 0;
    for (const Eigen::Vector3d& p : per_frame) sum_squares += (p - mean).squaredNorm();
    Landmark landmark;
    landmark.name = recipe.name;
    landmark.position_mm = mean;
    result.landmarks.landmarks.push_back(std::move(landmark));
    result.info.push_back({recipe.name, static_cast<int>(per_frame.size()),
                           std::sqrt(sum_squares / static_cast<double>(per_frame.size()))});
  }

  // Mean pelvis width and depth over the frames with every pelvis marker.
  double width = 0;
  double depth = 0;
  int count = 0;
  for (Eigen::Index f = 0; f < trial.num_frames(); ++f) {
    std::vector<Eigen::Vector3d> p;
    p.reserve(pelvis.size());
    for (const Eigen::Index marker : pelvis) p.emplace_back(trial.position(f, marker) * to_mm);
    if (!std::ranges::all_of(p, [](const Eigen::Vector3d& v) { return v.allFinite(); })) continue;
    const HarringtonHipCentres hips = harrington_hip_centres(p[0], p[1], posterior_point(p));
    width += hips.pelvis_width_mm;
    depth += hips.pelvis_depth_mm;
    ++count;
  }
  if (count > 0) {
    result.pelvis_width_mm = width / count;
    result.pelvis_depth_mm = depth / count;
  }
  return result;
}

}  // namespace mmm::landmarks

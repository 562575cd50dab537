#include "core/motion/tracking_setup.h"

#include <numbers>

#include "core/errors.h"
#include "core/suggest.h"

namespace mmm::motion {

TrackingSetup bind_tracking(const Skeleton& skeleton, const MarkerMapping& mapping,
                            const std::vector<std::string>& trial_markers) {
  TrackingSetup setup;
  std::vector<std::string> model_names;
  model_names.reserve(skeleton.markers.size());
  for (const SkeletonMarker& marker : skeleton.markers) model_names.push_back(marker.name);
  std::vector<bool> named(trial_markers.size(), false);
  for (const MarkerTask& task : mapping.markers) {
    const auto trial = std::find(trial_markers.begin(), trial_markers.end(), task.trial);
    const std::optional<int> model = skeleton.marker_index(task.model);
    if (trial != trial_markers.end()) {
      named[static_cast<std::size_t>(trial - trial_markers.begin())] = true;
    }
    if (trial == trial_markers.end()) {
      setup.not_in_trial.push_back(task.trial + did_you_mean(task.trial, trial_markers));
      continue;
    }
    if (!model) {
      setup.not_on_model.push_back(task.model + did_you_mean(task.model, model_names));
      continue;
    }
    if (task.weight <= 0) continue;
    setup.markers.push_back(
        {task.model, *model, static_cast<int>(trial - trial_markers.begin()), task.weight});
  }
  for (std::size_t i = 0; i < trial_markers.size(); ++i) {
    if (!named[i]) setup.trial_unused.push_back(trial_markers[i]);
  }
  std::vector<std::string> coordinate_names;
  coordinate_names.reserve(skeleton.coordinates.size());
  for (const SkeletonCoordinate& c : skeleton.coordinates) coordinate_names.push_back(c.name);
  for (const CoordinateTask& task : mapping.coordinates) {
    const std::optional<int> index = skeleton.coordinate_index(task.coordinate);
    if (!index) {
      setup.unknown_coordinates.push_back(task.coordinate +
                                          did_you_mean(task.coordinate, coordinate_names));
      continue;
    }
    const bool angle =
        skeleton.coordinates[static_cast<std::size_t>(*index)].unit == CoordinateUnit::kAngle;
    setup.coordinates.push_back(
        {*index, angle ? task.value * std::numbers::pi / 180.0 : task.value, task.weight});
  }
  int on_root = 0;
  for (const BoundMarker& marker : setup.markers) {
    if (skeleton
            .bodies[static_cast<std::size_t>(
                skeleton.markers[static_cast<std::size_t>(marker.model)].body)]
            .parent < 0) {
      ++on_root;
    }
  }
  if (on_root < 3) {
    const std::string root = skeleton.bodies.empty() ? "(none)" : skeleton.bodies.front().name;
    throw InvalidInputError(
        mapping.source.string() + ": only " + std::to_string(on_root) + " tracked marker(s) on '" +
        root + "' and " + std::to_string(setup.markers.size()) +
        " in all; at least 3 on the root are needed to place it (check the mapping's model names; "
        "mapped but not in the trial: " +
        join_names(setup.not_in_trial) + "; not on the model: " + join_names(setup.not_on_model) +
        ")");
  }
  return setup;
}

}  // namespace mmm::motion

#pragma once
// A marker mapping bound to one skeleton and one trial: which trial column
// drives which model marker with what weight, which coordinates are held,
// and what could not be matched (reported, not fatal: the shipped gait2392
// mapping names left-leg and torso markers a right-leg atlas does not have).

#include <string>
#include <vector>

#include "core/motion/marker_mapping.h"
#include "core/motion/skeleton.h"

namespace mmm::motion {

struct BoundMarker {
  std::string name;  // model marker
  int model = 0;     // index into Skeleton::markers
  int trial = 0;     // index into the trial's markers
  double weight = 1.0;
};

struct BoundCoordinateTask {
  int coordinate = 0;  // index into Skeleton::coordinates
  double value = 0.0;  // rad or mm
  double weight = 1.0;
};

struct TrackingSetup {
  std::vector<BoundMarker> markers;  // weight > 0 only
  std::vector<BoundCoordinateTask> coordinates;
  // Mapping entries skipped, one sentence each with did-you-mean hints.
  std::vector<std::string> not_in_trial;  // trial marker named by the mapping but absent
  std::vector<std::string> not_on_model;  // model marker named by the mapping but absent
  std::vector<std::string> unknown_coordinates;
  std::vector<std::string> trial_unused;  // trial markers the mapping does not name
};

// Binds `mapping` to `skeleton` and the trial's marker names. Throws
// InvalidInputError, naming the mapping file and the skipped names, when
// fewer than 3 markers of the skeleton's root body can be tracked: its six
// degrees of freedom would be free.
TrackingSetup bind_tracking(const Skeleton& skeleton, const MarkerMapping& mapping,
                            const std::vector<std::string>& trial_markers);

}  // namespace mmm::motion

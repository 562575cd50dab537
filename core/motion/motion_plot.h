#pragma once
// Joint angles over time as SVG small multiples: one panel per coordinate
// that moves, ours beside a reference (OpenSim's IK) when one is given.

#include <string>

#include "core/motion/motion_fusion.h"
#include "core/opensim/mot.h"

namespace mmm::motion {

struct AnglePlotOptions {
  std::string title;
  std::string ours_label = "mmm";
  std::string reference_label = "OpenSim IK";
  bool angles_only = true;     // leave out translations
  double min_range_deg = 0.5;  // leave out coordinates that barely move
  int columns = 3;
};

// Throws InvalidInputError from the plotting for inconsistent data.
std::string joint_angle_svg(const FusedMotion& motion, const opensim::StorageTable* reference,
                            const AnglePlotOptions& options = {});

}  // namespace mmm::motion

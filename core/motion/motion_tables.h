#pragma once
// Joint-angle tables of a fused motion in OpenSim's conventions, and their
// comparison with another table (OpenSim's own inverse kinematics).

#include <string>
#include <vector>

#include "core/motion/motion_fusion.h"
#include "core/opensim/mot.h"

namespace mmm::motion {

// The coordinates over time as an OpenSim storage table: angles in
// degrees, lengths in m (inDegrees=yes), as OpenSim's IK writes them;
// write_mot turns it into a .mot that OpenSim and its plotter open.
opensim::StorageTable coordinate_table(const FusedMotion& motion, const std::string& name);

struct CoordinateDifference {
  std::string coordinate;
  bool angle = true;  // deg; else mm
  int samples = 0;    // frames compared
  double rms = 0.0;   // RMS of ours - reference (deg or mm)
  double max_abs = 0.0;
  double mean = 0.0;             // mean offset (deg or mm)
  double reference_range = 0.0;  // max - min of the reference over the frames
};

// Per coordinate present in both, over our frames inside the reference's
// time span (the reference linearly interpolated at our times). The
// reference's angles are read as degrees when its in_degrees is set,
// lengths as m. Coordinates only one side has are skipped.
std::vector<CoordinateDifference> compare_coordinates(const FusedMotion& motion,
                                                      const opensim::StorageTable& reference);

}  // namespace mmm::motion

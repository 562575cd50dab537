#pragma once
// Moment arms and lengths of an action line over one coordinate swept through
// a range (the others at their defaults), and how two sweeps of the same line
// compare: how a biomechanist judges a model's muscle paths (against a
// reference model, e.g. gait2392's own paths evaluated the same way).
//
// Moment arm: OpenSim's convention, -dL/dq (action_line_path.h), in mm per
// radian; the sweep samples every `step_deg`.

#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/motion/skeleton.h"
#include "core/wrapping/action_line_path.h"

namespace mmm::wrapping {

struct CoordinateSweep {
  std::string coordinate;
  double from_deg = 0.0;
  double to_deg = 0.0;
};

// Hip flexion -20..90, adduction -30..30, rotation -40..40, knee flexion
// 0..120 (gait2392's knee_angle_r runs negative: -120..0), ankle -30..30 deg.
std::vector<CoordinateSweep> right_leg_sweeps();

struct LineSweep {
  std::string coordinate;
  std::vector<double> angles_deg;
  std::vector<double> moment_arm_mm;
  std::vector<double> length_mm;
};

// Throws InvalidInputError for an unknown coordinate or a step <= 0.
LineSweep sweep_line(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                     const atlas::ActionLine& line, const motion::Skeleton& skeleton,
                     const CoordinateSweep& sweep, double step_deg = 1.0,
                     const PathOptions& options = {});

struct SweepComparison {
  double rms_mm = 0.0;      // moment arm, line against reference, over the sweep
  double max_abs_mm = 0.0;  // largest difference
  int sign_checked = 0;     // samples where the reference's |moment arm| > sign_threshold
  int sign_disagrees = 0;   // ... of which the line's sign differs
  double max_arm_jump_mm_per_deg = 0.0;     // the line's largest change between samples, per deg
  double max_length_jump_mm_per_deg = 0.0;  // same for its length
};

// `line` and `reference` must sample the same angles.
SweepComparison compare_sweeps(const LineSweep& line, const LineSweep& reference,
                               double sign_threshold_mm = 10.0);

// Largest |change| between consecutive samples per degree.
double largest_jump_per_deg(const std::vector<double>& angles_deg,
                            const std::vector<double>& values);

}  // namespace mmm::wrapping

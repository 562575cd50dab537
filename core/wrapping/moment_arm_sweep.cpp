#include "core/wrapping/moment_arm_sweep.h"

#include <cmath>
#include <numbers>

#include "core/errors.h"

namespace mmm::wrapping {

std::vector<CoordinateSweep> right_leg_sweeps() {
  return {{"hip_flexion_r", -20, 90},
          {"hip_adduction_r", -30, 30},
          {"hip_rotation_r", -40, 40},
          {"knee_angle_r", -120, 0},
          {"ankle_angle_r", -30, 30}};
}

LineSweep sweep_line(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                     const atlas::ActionLine& line, const motion::Skeleton& skeleton,
                     const CoordinateSweep& sweep, double step_deg, const PathOptions& options) {
  const std::optional<int> index = skeleton.coordinate_index(sweep.coordinate);
  if (!index) {
    throw InvalidInputError("moment-arm sweep: the skeleton has no coordinate '" +
                            sweep.coordinate + "'");
  }
  if (!(step_deg > 0) || !(sweep.to_deg >= sweep.from_deg)) {
    throw InvalidInputError("moment-arm sweep of " + sweep.coordinate +
                            ": needs a positive step and from <= to");
  }
  LineSweep result;
  result.coordinate = sweep.coordinate;
  const int samples = static_cast<int>(std::floor((sweep.to_deg - sweep.from_deg) / step_deg)) + 1;
  Eigen::VectorXd q = skeleton.default_coordinates();
  for (int k = 0; k < samples; ++k) {
    const double angle = sweep.from_deg + k * step_deg;
    q(*index) = angle * std::numbers::pi / 180.0;
    result.angles_deg.push_back(angle);
    result.length_mm.push_back(action_line_path(atlas, muscle, line, skeleton, q, options).length);
    result.moment_arm_mm.push_back(moment_arm(atlas, muscle, line, skeleton, q, *index, options));
  }
  return result;
}

double largest_jump_per_deg(const std::vector<double>& angles_deg,
                            const std::vector<double>& values) {
  double largest = 0.0;
  for (std::size_t i = 1; i < values.size() && i < angles_deg.size(); ++i) {
    const double step = std::abs(angles_deg[i] - angles_deg[i - 1]);
    if (step > 0) largest = std::max(largest, std::abs(values[i] - values[i - 1]) / step);
  }
  return largest;
}

SweepComparison compare_sweeps(const LineSweep& line, const LineSweep& reference,
                               double sign_threshold_mm) {
  if (line.angles_deg != reference.angles_deg) {
    throw InvalidInputError("compare_sweeps: the two sweeps of " + line.coordinate +
                            " sample different angles");
  }
  SweepComparison comparison;
  double squares = 0.0;
  for (std::size_t i = 0; i < line.moment_arm_mm.size(); ++i) {
    const double difference = line.moment_arm_mm[i] - reference.moment_arm_mm[i];
    squares += difference * difference;
    comparison.max_abs_mm = std::max(comparison.max_abs_mm, std::abs(difference));
    if (std::abs(reference.moment_arm_mm[i]) > sign_threshold_mm) {
      ++comparison.sign_checked;
      if (line.moment_arm_mm[i] * reference.moment_arm_mm[i] <= 0) ++comparison.sign_disagrees;
    }
  }
  if (!line.moment_arm_mm.empty()) {
    comparison.rms_mm = std::sqrt(squares / static_cast<double>(line.moment_arm_mm.size()));
  }
  comparison.max_arm_jump_mm_per_deg = largest_jump_per_deg(line.angles_deg, line.moment_arm_mm);
  comparison.max_length_jump_mm_per_deg = largest_jump_per_deg(line.angles_deg, line.length_mm);
  return comparison;
}

}  // namespace mmm::wrapping

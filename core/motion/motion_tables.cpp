#include "core/motion/motion_tables.h"

#include <cmath>
#include <limits>
#include <numbers>

namespace mmm::motion {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr double kMPerMm = 1e-3;

}  // namespace

opensim::StorageTable coordinate_table(const FusedMotion& motion, const std::string& name) {
  opensim::StorageTable table;
  table.name = name;
  table.in_degrees = true;
  table.in_degrees_stated = true;
  table.column_names = motion.coordinate_names;
  table.times = motion.times;
  table.values = motion.coordinates;
  for (std::size_t c = 0; c < motion.coordinate_units.size(); ++c) {
    table.values.col(static_cast<Eigen::Index>(c)) *=
        motion.coordinate_units[c] == CoordinateUnit::kAngle ? kDegPerRad : kMPerMm;
  }
  return table;
}

std::vector<CoordinateDifference> compare_coordinates(const FusedMotion& motion,
                                                      const opensim::StorageTable& reference) {
  std::vector<CoordinateDifference> differences;
  if (reference.num_rows() == 0) return differences;
  const double first = reference.times(0);
  const double last = reference.times(reference.num_rows() - 1);
  const double angle_unit = reference.in_degrees ? 1.0 : kDegPerRad;
  for (std::size_t c = 0; c < motion.coordinate_names.size(); ++c) {
    const std::optional<Eigen::Index> column = reference.column_index(motion.coordinate_names[c]);
    if (!column) continue;
    CoordinateDifference difference;
    difference.coordinate = motion.coordinate_names[c];
    difference.angle = motion.coordinate_units[c] == CoordinateUnit::kAngle;
    double squares = 0.0;
    double sum = 0.0;
    double low = std::numeric_limits<double>::infinity();
    double high = -low;
    for (Eigen::Index k = 0; k < motion.num_frames(); ++k) {
      const double t = motion.times(k);
      if (t < first - 1e-9 || t > last + 1e-9) continue;
      const double clamped = std::clamp(t, first, last);
      const double theirs_raw = reference.interpolate(clamped)(*column);
      const double theirs = difference.angle ? theirs_raw * angle_unit : theirs_raw / kMPerMm;
      const double ours = difference.angle
                              ? motion.coordinates(k, static_cast<Eigen::Index>(c)) * kDegPerRad
                              : motion.coordinates(k, static_cast<Eigen::Index>(c));
      if (!std::isfinite(theirs)) continue;
      const double d = ours - theirs;
      squares += d * d;
      sum += d;
      difference.max_abs = std::max(difference.max_abs, std::abs(d));
      low = std::min(low, theirs);
      high = std::max(high, theirs);
      ++difference.samples;
    }
    if (difference.samples == 0) continue;
    difference.rms = std::sqrt(squares / difference.samples);
    difference.mean = sum / difference.samples;
    difference.reference_range = high - low;
    differences.push_back(difference);
  }
  return differences;
}

}  // namespace mmm::motion

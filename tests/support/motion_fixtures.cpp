#include "tests/support/motion_fixtures.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/opensim/osim_model.h"
#include "tests/support/test_data.h"

namespace mmm::test {

const motion::Skeleton& subject01_skeleton() {
  static const motion::Skeleton skeleton = motion::skeleton_from_osim(opensim::read_osim(
      data_dir() / "gait2392" / "Pipelines" / "reference" / "subject01_simbody.osim"));
  return skeleton;
}

namespace {

// Whether any marker sits on a body the coordinate moves (otherwise no
// marker trial can tell its value).
bool moves_a_marker(const motion::Skeleton& skeleton, int coordinate) {
  const std::vector<int> moved = skeleton.bodies_moved_by(coordinate);
  return std::ranges::any_of(skeleton.markers, [&](const motion::SkeletonMarker& marker) {
    return std::find(moved.begin(), moved.end(), marker.body) != moved.end();
  });
}

}  // namespace

Eigen::MatrixXd synthetic_coordinates(const motion::Skeleton& skeleton, int frames) {
  Eigen::MatrixXd q(frames, skeleton.num_coordinates());
  for (int c = 0; c < skeleton.num_coordinates(); ++c) {
    const motion::SkeletonCoordinate& coordinate =
        skeleton.coordinates[static_cast<std::size_t>(c)];
    const bool length = coordinate.unit == motion::CoordinateUnit::kLength;
    // Gait-like: 20 degrees (or 20 mm), one cycle per second, each
    // coordinate with its own phase; kept well inside its range.
    const double half_range = 0.5 * (coordinate.upper - coordinate.lower);
    const double amplitude =
        std::min(length ? 20.0 : 20.0 * std::numbers::pi / 180.0, 0.4 * std::max(half_range, 0.0));
    const double centre = std::clamp(coordinate.default_value, coordinate.lower + amplitude,
                                     coordinate.upper - amplitude);
    for (int f = 0; f < frames; ++f) {
      const double t = f / 60.0;
      double value = centre + amplitude * std::sin(2.0 * std::numbers::pi * t + 0.7 * c);
      if (coordinate.locked || !moves_a_marker(skeleton, c)) value = coordinate.default_value;
      if (coordinate.name.ends_with("_tx")) value = 1200.0 * t;  // walking along x
      if (coordinate.name.ends_with("_ty")) value = 950.0 + 20.0 * std::sin(4.0 * 3.14159 * t);
      q(f, c) = value;
    }
  }
  return q;
}

opensim::MarkerTrajectories synthetic_trial(const motion::Skeleton& skeleton,
                                            const Eigen::MatrixXd& coordinates) {
  opensim::MarkerTrajectories trial;
  trial.source = "synthetic.trc";
  trial.data_rate = trial.camera_rate = trial.orig_data_rate = 60.0;
  trial.units = "mm";
  const auto frames = coordinates.rows();
  trial.orig_num_frames = static_cast<int>(frames);
  for (const motion::SkeletonMarker& marker : skeleton.markers) {
    trial.marker_names.push_back(marker.name);
  }
  trial.times.resize(frames);
  trial.positions.resize(frames, 3 * static_cast<Eigen::Index>(skeleton.markers.size()));
  motion::SkeletonPose pose(skeleton);
  for (Eigen::Index f = 0; f < frames; ++f) {
    trial.frame_numbers.push_back(static_cast<int>(f) + 1);
    trial.times(f) = static_cast<double>(f) / 60.0;
    pose.set(coordinates.row(f).transpose());
    for (std::size_t m = 0; m < skeleton.markers.size(); ++m) {
      trial.positions.block<1, 3>(f, 3 * static_cast<Eigen::Index>(m)) =
          pose.marker(static_cast<int>(m)).transpose();
    }
  }
  return trial;
}

}  // namespace mmm::test

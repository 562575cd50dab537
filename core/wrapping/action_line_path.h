#pragma once
// The path of a muscle's action line in one pose of a moving skeleton, its
// length and its moment arms: origin -> via points -> insertion, each point
// carried by its bone (conditional points only while their coordinate is
// in range, moving points through their functions of the coordinates),
// each straight segment wrapped over the line's obstacles it would pass
// through (obstacle_set.h; obstacles ride on their bones too).
//
// Moment arm about a coordinate, OpenSim's convention: r = -dL/dq (mm per
// rad), by central differences of the path length. Conditional points fade
// in and out (PathOptions::conditional_blend), so length and moment arm stay
// continuous where OpenSim's path jumps.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/motion/skeleton.h"
#include "core/wrapping/obstacle_set.h"

namespace mmm::wrapping {

struct ActionLinePath {
  std::vector<Eigen::Vector3d> points;  // the whole path, wrapped parts included (world, mm)
  std::vector<std::string> active;      // names of the path points in use, in order
  // Per entry of `points`: its path point's name ("" on a wrap) and the bone
  // carrying it (on a wrap: the obstacle's bone).
  std::vector<std::string> point_names;
  std::vector<std::string> point_bones;
  // mm: of the line of action, the model's points and their wraps; points
  // that follow the line (kFollowsLine) bend `points` through the muscle but
  // do not count here, nor in the moment arms.
  double length = 0.0;
  int wraps = 0;                 // segments that wrapped over an obstacle
  bool inside_obstacle = false;  // a path point lies inside an obstacle
};

struct PathOptions {
  WrapOptions wrap;
  double derivative_step = 1e-4;  // rad (or mm) for the moment arms' central differences
  // A conditional point fades in over this much of its coordinate (rad, or
  // mm) inside each end of its range: at the end of the range it lies on the
  // segment between its neighbours, so switching it on or off changes
  // neither the length nor the moment arm (smoothstep weight). At most half
  // the range. 0: OpenSim's abrupt switch (a jump in length, and a spike in
  // the moment arm, wherever the point is off the line when it switches).
  double conditional_blend = 0.17453292519943295;  // 10 deg
};

// `skeleton` must be built from `atlas` (motion::skeleton_from_atlas), or
// share its bone names with body frames equal to the bones' frames; q its
// coordinates. Throws InvalidInputError when a point's bone, a coordinate
// of a conditional or moving point, or a named obstacle is unknown, or an
// obstacle has invalid dimensions (e.g. an ellipsoid with a zero semi-axis).
ActionLinePath action_line_path(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                                const atlas::ActionLine& line, const motion::Skeleton& skeleton,
                                const Eigen::VectorXd& q, const PathOptions& options = {});

// -dL/dq of the line about `coordinate` at q (mm per rad, or per mm).
double moment_arm(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                  const atlas::ActionLine& line, const motion::Skeleton& skeleton,
                  const Eigen::VectorXd& q, int coordinate, const PathOptions& options = {});

}  // namespace mmm::wrapping

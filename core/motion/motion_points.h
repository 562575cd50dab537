#pragma once
// Where the atlas's anatomy is in every frame of a fused motion: landmarks,
// attachment-area centroids, action-line points (conditional points with
// whether they are active, moving points through their functions of the
// frame's coordinates) and markers, each carried by its bone's pose.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/atlas/atlas.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/skeleton.h"

namespace mmm::motion {

struct TrackedPoint {
  std::string kind;     // "landmark", "origin", "insertion", "path_point", "marker"
  std::string element;  // the landmark/marker, or "muscle/line" and "muscle" for areas
  std::string name;     // point name (path points), area index, or the element again
  std::string bone;
};

struct PointTrajectories {
  std::vector<TrackedPoint> points;
  Eigen::MatrixXd positions;  // #frames by 3 #points (mm, lab frame)
  Eigen::MatrixXi active;     // #frames by #points: 0 for an inactive conditional point
};

// The atlas must be the one the skeleton was built from (skeleton_from_atlas).
// Throws InvalidInputError when an element's bone or a moving point's
// coordinate is not in the skeleton.
PointTrajectories atlas_point_trajectories(const atlas::Atlas& atlas, const Skeleton& skeleton,
                                           const FusedMotion& motion);

// The skeleton's markers only (any skeleton).
PointTrajectories marker_trajectories(const Skeleton& skeleton, const FusedMotion& motion);

// CSV: frame,time_s,kind,element,name,bone,x_mm,y_mm,z_mm,active (one row per
// point per frame; names quoted when they hold a comma or quote).
std::string point_trajectories_csv(const PointTrajectories& points, const FusedMotion& motion);

// A stick figure of a pose: for every body with a parent, a segment from
// the parent's joint centre to its own (child-frame origins, mm).
struct StickFigure {
  Eigen::MatrixX3d points;
  std::vector<std::array<int, 2>> segments;
};
StickFigure stick_figure(const Skeleton& skeleton, const std::vector<Eigen::Isometry3d>& poses);

}  // namespace mmm::motion

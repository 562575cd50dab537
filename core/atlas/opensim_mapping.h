#pragma once
// Brings the parts of an OpenSim model that hang on its bodies — joints,
// muscle paths, wrap objects, markers — into the atlas frame, through one
// affine map per body (ground at the default pose, m -> atlas, mm; see
// bone_registration.h).
//
// Frames (bone frames, joint frames, wrap-object poses) take the map's
// nearest rotation and the mapped origin. Joint translation functions,
// moving path-point functions and wrap-object sizes are scaled by the
// body's uniform scale (cube root of det A), so lengths come out in mm; the
// anisotropic part of a map acts on points, not on these functions.
// The rest value of each joint coordinate is the value whose joint motion
// best reproduces the relative pose of the two mapped joint frames (Gauss-
// Newton on rotation (rad) and translation (per 10 mm) residuals), so that
// the atlas at rest is the subject's own pose.

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/opensim/osim_model.h"

namespace mmm::atlas {

struct BodyMaps {
  std::map<std::string, Eigen::Affine3d> map;       // body -> (ground m -> atlas mm)
  std::map<std::string, Eigen::Isometry3d> pose;    // body -> ground, default pose (m)
  std::map<std::string, std::string> primary_bone;  // body -> atlas bone that stands for it

  [[nodiscard]] bool has(const std::string& body) const { return map.contains(body); }
  // Uniform scale of a body's map (mm per m).
  [[nodiscard]] double scale(const std::string& body) const;
  // A point fixed to `body`, given in its body frame (m), in the atlas (mm).
  [[nodiscard]] Eigen::Vector3d point(const std::string& body, const Eigen::Vector3d& local) const;
  // A frame of the ground at the default pose (m), in the atlas (mm).
  [[nodiscard]] Eigen::Isometry3d frame(const std::string& body,
                                        const Eigen::Isometry3d& ground_frame) const;
};

struct MappedJoint {
  Joint joint;
  double mismatch_mm = 0.0;
  double mismatch_deg = 0.0;
};

// The joint, with frames, coordinates (ranges in rad or mm), axes and rest
// values. Throws InvalidInputError when a body of the joint has no map.
MappedJoint map_joint(const opensim::Joint& source, const BodyMaps& maps);

// The action line of an OpenSim muscle; wrap objects it uses are appended to
// `obstacles` (once each). `rest` holds the atlas's coordinate rest values
// (conditional and moving points are evaluated there). Throws
// InvalidInputError when a path point's body has no map; unsupported wrap
// shapes (torus) are skipped and named in `notes`.
ActionLine map_action_line(const opensim::OsimModel& model, const opensim::Muscle& muscle,
                           const BodyMaps& maps, const std::map<std::string, double>& rest,
                           std::vector<WrapObstacle>& obstacles, std::vector<std::string>& notes);

}  // namespace mmm::atlas

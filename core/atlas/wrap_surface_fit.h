#pragma once
// Wrap surfaces fitted to the atlas's own bones: a sphere, cylinder or
// ellipsoid through the bone's surface in a region (bone vertices within a
// radius of a centre, optionally only those on one side of it), as musculo-
// skeletal models place them by hand (gait2392's successors: the femoral
// condyles for gastrocnemius and the knee extensors, the pelvic brim for
// iliacus and psoas, ...).
//
//   region: vertices v of the bone with |v - centre| <= radius and, with a
//     region side d, (v - centre).d >= 0
//   fit: sphere_fit / cylinder_fit (axis from the hint, e.g. the joint's
//     axis) / ellipsoid_fit, in the atlas frame at rest
//   frame: for a cylinder z along its axis; x along the wrap side (across
//     the axis), so quadrant "+x" lets lines wrap on that side only; an
//     ellipsoid's principal axes are ordered so that x is the one closest to
//     the wrap side
//   offset: added to the fitted radii (lines of action run through their
//     muscles' middles, away from the bone)
//   clearance: the path points the surface must leave outside (the lines'
//     own fixed points, which sit on or near the same bone surface) are
//     kept at least `clearance_mm` outside by shrinking the surface about its
//     centre (uniformly), reported
// Throws InvalidInputError when the region holds too few vertices to fit.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"

namespace mmm::atlas {

struct WrapSurfaceRegion {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // atlas, rest (mm)
  double radius_mm = 30.0;
  std::optional<Eigen::Vector3d> side;  // keep only vertices on this side of the centre (atlas)
  double offset_mm = 0.0;               // added to the fitted radii
};

struct NamedPoint {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

struct WrapSurfaceFitReport {
  std::string name;
  std::string bone;
  WrapShape shape = WrapShape::kSphere;
  int vertices = 0;       // bone vertices in the region
  double rms_mm = 0.0;    // of the fit through them
  double shrink = 1.0;    // factor applied so the kept points lie outside (1: none)
  std::string shrunk_by;  // the point that asked for the smallest factor
  Eigen::Vector3d radii = Eigen::Vector3d::Zero();  // as used (WrapObstacle::radii)
};

// Fits `shape` to the vertices of `bone_vertices` (#V by 3, atlas, rest) in
// `region`, as the obstacle `name` riding on `bone`. Lines wrap only on the
// side `wrap_side` (atlas direction; all round when absent). `axis_hint`
// starts a cylinder's axis (its sign is kept); `outside` are points the
// surface must leave `clearance_mm` outside.
WrapObstacle fit_wrap_surface(const std::string& name, const std::string& bone, WrapShape shape,
                              const Eigen::MatrixX3d& bone_vertices,
                              const WrapSurfaceRegion& region,
                              const std::optional<Eigen::Vector3d>& wrap_side,
                              const std::optional<Eigen::Vector3d>& axis_hint,
                              const std::vector<NamedPoint>& outside, double clearance_mm,
                              WrapSurfaceFitReport* report = nullptr);

// How far `point` lies outside `obstacle` (negative inside; for an ellipsoid
// along the ray from its centre; a cylinder is infinite along its axis), mm.
double distance_outside(const WrapObstacle& obstacle, const Eigen::Vector3d& point);

}  // namespace mmm::atlas

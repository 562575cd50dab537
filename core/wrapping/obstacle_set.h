#pragma once
// Obstacle-set wrapping (Garner & Pandy 2000, "The obstacle-set method for
// representing muscle paths in musculoskeletal models"): the shortest path
// of a muscle's action line from P to S that stays outside an analytic
// obstacle, in closed form.
//
//   sphere   (centre c, radius r): the geodesic lies in the plane through
//            c, P and S; straight to the tangent point T1, along the great
//            circle to T2, straight to S. Length
//              sqrt(|P-c|^2 - r^2) + r * theta + sqrt(|S-c|^2 - r^2)
//   cylinder (axis z of its frame, radius r, infinite): unroll the surface.
//            In the xy-plane the path is the 2D sphere case on the circle;
//            z grows linearly with the unrolled length, so the wrapped part
//            is a helix and the length is sqrt(L_xy^2 + (z_S - z_P)^2).
//   ellipsoid (semi-axes radii along its frame's x, y, z): no closed form;
//            the sphere case in the space where it is the unit sphere gives
//            the tangent lines and a first path, relaxed numerically onto a
//            geodesic (ellipsoid_geodesic.h).
//
// The path wraps only when the straight segment P-S would pass through the
// obstacle (for the cylinder: its xy-projection through the circle) and,
// with a quadrant ("+x", "-y", ...: the side of the obstacle, in its frame,
// the path may wrap on), only on that side: a straight line outside the
// allowed side is left straight, a path that must wrap goes around it.
// An end point inside the obstacle (a moving insertion that comes close to
// the bone the obstacle stands for) has no wrapping path: by default the
// obstacle is shrunk about its centre for that segment until the point lies
// just outside it (0.999 of its distance; the shrinking starts smoothly
// from 30 % of the size around the surface), so the path, its length and
// the moment arm stay continuous as the point goes in; OpenSim's behaviour, a
// straight segment (a jump in length), is the other choice. Either way the
// result is flagged `inside`.

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace mmm::wrapping {

enum class ObstacleShape { kSphere, kCylinder, kEllipsoid };

struct Obstacle {
  ObstacleShape shape = ObstacleShape::kSphere;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // obstacle frame -> world (mm)
  double radius = 0.0;                                     // sphere, cylinder: mm, > 0
  // Ellipsoid: semi-axes along the obstacle frame's x, y, z (mm, each > 0).
  Eigen::Vector3d radii = Eigen::Vector3d::Zero();
  // "all", "+x", "-x", "+y", "-y", "+z", "-z" (cylinder: x or y only)
  std::string quadrant = "all";
};

struct WrapResult {
  bool wrapped = false;  // the path touches the obstacle
  bool inside = false;   // P or S lies inside the obstacle (see WrapOptions)
  Eigen::Vector3d tangent_in = Eigen::Vector3d::Zero();   // T1 (world, mm) when wrapped
  Eigen::Vector3d tangent_out = Eigen::Vector3d::Zero();  // T2
  // rad swept on the obstacle (in the xy-plane for a cylinder; for an
  // ellipsoid, the angle its surface normal turns through along the path)
  double wrap_angle = 0.0;
  double length = 0.0;  // of the whole path P -> S (mm)
  // The path as a polyline P, T1, points on the surface every
  // `arc_step_mm` at most, T2, S (just P, S when not wrapped).
  std::vector<Eigen::Vector3d> points;
};

struct WrapOptions {
  double arc_step_mm = 2.0;  // resolution of the wrapped part of `points`
  // An end point inside: shrink the obstacle to it (continuous), or leave
  // the segment straight (OpenSim).
  bool shrink_to_inside_points = true;
};

// Throws InvalidInputError for a non-positive radius (an ellipsoid: radii),
// an unknown quadrant or non-finite points; SolverError when an ellipsoid's
// geodesic cannot be found.
WrapResult wrap_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& s,
                        const Obstacle& obstacle, const WrapOptions& options = {});

}  // namespace mmm::wrapping

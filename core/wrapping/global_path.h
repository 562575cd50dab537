#pragma once
// Global muscle paths (Audenaert & Audenaert 2008, "Global optimization
// method for muscle path wrapping"): the shortest path through a muscle's
// fixed points (origin, via points, insertion) that keeps a clearance c from
// the bone surfaces themselves, meshes rather than fitted primitives.
//
// Each segment between consecutive fixed points a, b is a polyline
// a, x_1 .. x_N, b whose interior points solve
//   min  sum_i |x_{i+1} - x_i|^2   subject to  sd_s(x_i) >= c  for every surface s
// (sd_s: signed distance, negative inside). The energy's minimisers are the
// shortest paths with evenly spaced points (the discrete geodesic energy).
// The constraint is handled by an active set rather than a penalty: points
// in contact slide on the offset surface {sd = c} of their surface (a Ceres
// Manifold: tangent basis from the distance gradient
//   grad sd(x) = sign * (x - closest(x)) / |x - closest(x)|,
// retraction closest(y) + c grad sd(y)), the others are free; Ceres
// (Levenberg-Marquardt, analytic Jacobians) solves with the set fixed, then
//   free a contact the path pulls off its surface (peeled from both ends:
//     x_i goes when the chord from the last contact kept to x_{i+1} passes
//     outside it)
//   put a free point closer than c to a surface onto its offset surface
// and solve again until the set holds. (A penalty w * max(0, c - sd) per
// point and surface, tried first, needed 2-4 times the iterations: a
// Gauss-Newton step cannot see a surface under a point that is not yet in
// contact, steps cut through it and the trust region collapses.)
//
//   relevant = surfaces whose world box meets the box of a, b (and the warm
//              start) inflated by search_margin_mm + c
//   lift an end closer than c to a surface (an attachment on or in a bone)
//     onto the offset surface: the path leaves it along the gradient
//   if the straight line keeps its clearance: done, it is the path
//   start = the previous frame's polyline, its ends moved onto a, b and
//           resampled (warm start), or else the straight line a-b, pushed
//           sideways out of the surfaces (per run of points inside, the
//           least displacement of 4 directions)
//   settle the active set (above); respread the points over the path's
//   length and settle again; surfaces near the path that were not relevant
//   join when the path runs into one
//
// Signed distances: the closest point from the surface's AabbTree; the sign
// from the closest face's normal when the closest point is inside that face
// (exact for a closed, consistently oriented mesh), else from the
// SignedDistance's winding number. Points outside a surface's box need no
// query, and each point remembers its last distance and closest point: a
// point that moved less than that distance keeps its side and a lower bound
// (often enough to skip the query), and the distance to the old closest
// point bounds the new query (which prunes the tree).
//
// Limits: clearance is enforced at the points only; a chord between two
// points in contact cuts a surface of curvature radius rho by its sagitta
// h^2 / (8 (rho + c)), so keep h^2 < 8 c (rho + c). The path is a local
// minimum: a cold start may settle on the longer side of a bone where a
// warm start that tracked the motion keeps the shorter one.

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "core/mesh/signed_distance.h"

namespace mmm::wrapping {

// A surface placed in the world: its signed distance built once in the
// surface's own frame (e.g. a bone's local frame), queried at pose^-1 * x.
struct PosedSurface {
  const mesh::SignedDistance* sdf = nullptr;               // not owned; must outlive the call
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // surface frame -> world (mm)
};

struct GlobalPathOptions {
  double clearance_mm = 1.0;      // c: the distance kept from every surface (>= 0)
  double max_spacing_mm = 5.0;    // h: largest distance between path points (> 0)
  int min_interior_points = 2;    // N at least this (>= 1) ...
  int max_interior_points = 100;  // ... and at most this, whatever the length
  // A surface is queried for a segment when its world box, inflated by the
  // clearance, meets the box of the segment's points inflated by this (mm).
  double search_margin_mm = 10.0;
  // A segment touches a surface when a point comes within clearance + this.
  double contact_tolerance_mm = 0.05;
  int max_iterations = 200;  // Ceres iterations per segment, over all its solves
  double function_tolerance = 1e-10;
  double parameter_tolerance = 1e-10;
  double gradient_tolerance = 1e-12;
};

// One segment of the path, between two consecutive fixed points.
struct GlobalSegment {
  // a, [a lifted], x_1 .. x_N, [b lifted], b (world, mm): an end closer
  // than the clearance to a surface is followed (preceded) by its lift.
  std::vector<Eigen::Vector3d> points;
  double length = 0.0;  // of the polyline (mm)
  // An interior point is within clearance + contact_tolerance_mm of a
  // surface, or an end was lifted off one.
  bool touches = false;
  // max over interior points and surfaces of -sd (mm): > 0 when a point is
  // inside a surface, ~ -clearance when the path rests on one; exact down to
  // -clearance, and -clearance when every point keeps its clearance.
  double max_penetration = 0.0;
  bool start_inside = false;  // the fixed point a lies inside a surface
  bool end_inside = false;    // the fixed point b lies inside a surface
  bool converged = true;      // the last solve converged and the active set held
  int iterations = 0;         // Ceres iterations, over all solves (0: no solve needed)
  std::vector<int> surfaces;  // indices of the surfaces queried for this segment
};

struct GlobalPath {
  std::vector<GlobalSegment> segments;  // one per pair of consecutive fixed points
  std::vector<Eigen::Vector3d> points;  // the whole polyline, fixed points included (world, mm)
  double length = 0.0;                  // mm
};

// The shortest path through `fixed_points` (#P >= 2, world, mm) that keeps
// options.clearance_mm from every surface. `warm_start` (optional): the
// path of a previous, nearby pose (the last frame of a motion); used per
// segment when it has as many segments, else ignored. Throws
// InvalidInputError on fewer than 2 or non-finite fixed points, a surface
// without a signed distance or with a non-finite pose, invalid options or a
// non-finite warm start.
GlobalPath global_path(const std::vector<Eigen::Vector3d>& fixed_points,
                       const std::vector<PosedSurface>& surfaces,
                       const GlobalPathOptions& options = {},
                       const GlobalPath* warm_start = nullptr);

// One segment from a to b. `warm_start`: a previous polyline of this segment
// (its ends are moved onto a and b and it is resampled), or empty for a
// cold start. Throws as global_path.
GlobalSegment global_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const std::vector<PosedSurface>& surfaces,
                             const GlobalPathOptions& options = {},
                             std::span<const Eigen::Vector3d> warm_start = {});

// World bounds of a posed surface (its tree's bounds, transformed; mm).
Eigen::AlignedBox3d world_bounds(const PosedSurface& surface);

// Indices of the surfaces worth querying for a path near `points`: those
// whose world box inflated by `margin_mm` meets the points' box (ascending).
std::vector<int> surfaces_near(std::span<const Eigen::Vector3d> points,
                               const std::vector<PosedSurface>& surfaces, double margin_mm);

}  // namespace mmm::wrapping

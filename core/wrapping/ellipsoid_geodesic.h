#pragma once
// The obstacle-set wrap over an ellipsoid (semi-axes r = (r_x, r_y, r_z)
// along its frame's axes), which has no closed form: straight from P to the
// tangent point T1, along a geodesic of the surface to T2, straight to S.
//
// The affine map D = diag(r) takes the unit sphere onto the ellipsoid and
// keeps lines and tangency, so the sphere case in the unit sphere's space
// (P' = D^-1 P, S' = D^-1 S, obstacle_set.h) decides whether the path wraps,
// on which side (the quadrant), and gives a first path: D * (great circle),
// whose straight parts are already tangent. Its wrapped part, as M points
// x_i = D u_i with |u_i| = 1 (Ceres SphereManifold), is then relaxed
// (Levenberg-Marquardt, analytic Jacobians):
//   min  |P - x_1| + lambda * sum_i |x_{i+1} - x_i|^2 + |x_M - S|
//   lambda = (M - 1) / (2 g),  g the wrapped part's length at the last pass
// The energy term spaces the points evenly along a geodesic; with that
// lambda a mm more of wrapped length costs what a mm of straight part does,
// so the tangency conditions are the shortest path's (a few passes make g
// and lambda agree). The wrapped length sums each chord's arc,
//   chord * (1 + kappa^2 chord^2 / 24),
// kappa the surface's normal curvature along the chord at its midpoint
// (exact to O(chord^4): a geodesic's curvature is the normal curvature).
// Equal radii give back the sphere's great circle. A quadrant that sends
// the path the long way round holds it to the plane through P, S and the
// centre (exact for a sphere; for an ellipsoid the long-way geodesic is no
// local minimum off that plane: free, the path would slide back to the
// short way).

#include <Eigen/Core>

#include "core/wrapping/obstacle_set.h"

namespace mmm::wrapping {

// p, s in the world (mm); obstacle.shape kEllipsoid with obstacle.radii > 0
// (checked by wrap_segment, which dispatches here). The result's points are
// P, M points on the surface every options.arc_step_mm at most, S; its
// wrap_angle is the angle the surface normal turns through along the
// wrapped part (the swept angle for a sphere). Throws SolverError when the
// relaxation fails.
WrapResult wrap_ellipsoid(const Eigen::Vector3d& p, const Eigen::Vector3d& s,
                          const Obstacle& obstacle, const WrapOptions& options);

}  // namespace mmm::wrapping

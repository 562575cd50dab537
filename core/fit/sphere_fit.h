#pragma once
// Least-squares sphere through a point set: centre and radius minimising the
// sum of squared distances from the points to the sphere. Used for the
// femoral head (hip joint centre) and other ball-shaped joint surfaces.
//
//   normalise: q_i = (p_i - mean) / spread        (conditioning)
//   reject coplanar input (covariance of q singular: no unique sphere)
//   algebraic start (Kasa 1976): |q|^2 = 2 c.q + d, linear least squares in
//     (c, d); r^2 = d + |c|^2
//   geometric refinement: Levenberg-Marquardt on e_i = |q_i - c| - r
//     (Marquardt 1963; Ahn, Rauh & Warnecke 2001, "Least-squares orthogonal
//     distances fitting of circle, sphere, ellipse, hyperbola, and parabola")
//   undo the normalisation
// The algebraic fit alone is exact for exact data but biased with noise on a
// partial sphere (it weights residuals by distance and shrinks the radius of a
// small cap); the geometric fit is the maximum-likelihood estimate under
// isotropic Gaussian noise.

#include <Eigen/Core>

namespace mmm::fit {

struct SphereFitOptions {
  // Refine the algebraic fit by minimising the geometric distances. Without
  // it the result is the algebraic (Kasa) fit.
  bool refine = true;
  // Most Levenberg-Marquardt iterations (>= 0). From the algebraic start a
  // few are usually enough; a noisy small cap can take a few tens.
  int max_iterations = 100;
  // Converged when a step moves centre and radius by less than this, relative
  // to the spread of the points (RMS distance to their mean), or when the
  // sum of squared residuals drops by less than this fraction.
  double tolerance = 1e-14;
};

struct SphereFitResult {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // mm
  double radius = 0;                                 // mm
  // sqrt(mean of (|p_i - center| - radius)^2), the RMS distance of the points
  // to the sphere (mm).
  double rms = 0;
  int iterations = 0;      // Levenberg-Marquardt iterations taken
  bool converged = false;  // tolerance reached (always true when !refine)
};

// Fits a sphere to `points`.
//   points  #P by 3 positions (mm), #P >= 4, not all in one plane
// Throws InvalidInputError for fewer than 4 points, a non-finite coordinate,
// or points that lie in a plane (or on a line, or coincide) up to rounding:
// their thickness across the thinnest direction is below 1e-6 of their extent,
// so no sphere (or every sphere through a circle) fits them. Throws
// SolverError when the fit gives non-finite numbers.
SphereFitResult sphere_fit(const Eigen::MatrixX3d& points, const SphereFitOptions& options = {});

}  // namespace mmm::fit

#pragma once
// The "Cadaver Fibres" (CF) muscle decomposition (VPHOP deliverable D10.2,
// section 3.4.3): fibres measured on a muscle's surface during an autopsy,
// interpolated over the surface with Kruger's constrained cubic spline, then
// carried into the muscle along inward rays.
//
//   along:  each measured polyline, parameterised by normalised arc length t,
//           is resampled at t_i = i / segments (i = 0..segments) by a
//           ConstrainedSpline per coordinate.
//   across: measured fibre f gets the knot u_f, its cumulative chord to
//           fibre 0 averaged over all t_i, normalised to [0, 1]. At each t_i,
//           a ConstrainedSpline per coordinate through the measured fibres'
//           points at (u_f) is sampled at u_j = j / (surface_fibres - 1), and
//           each sample is moved to its closest point of the surface: surface
//           fibre j, vertex i, point p_ij.
//   inward: d_ij = minus the surface normal at p_ij (the angle-weighted vertex
//           normals of its triangle, interpolated barycentrically; the
//           triangle's normal where they cancel). The ray p_ij + s d_ij
//           leaves the muscle at its first crossing, beyond 1e-6 of the
//           bounding-box diagonal, of a triangle that faces along the ray
//           (outward normal . d_ij > 0): chord length L_ij.
//   depth:  layer k (k = 0..depth_layers - 1) of surface fibre j has vertex i
//           at p_ij + k / (depth_layers - 1) L_ij d_ij: the chord sampled
//           uniformly including both end points, so layer 0 is the surface
//           fibre and the last layer lies on the opposite surface.
//
// A ray without such a crossing (an open or inward-oriented mesh) "misses"
// and is counted, and so is a point without a normal (a degenerate triangle
// whose vertex normals cancel; its layers stay at p_ij). A missing chord
// length is interpolated linearly in i between the nearest vertices of the
// same surface fibre whose rays did hit (the nearest one's beyond the last
// hit), and is 0 when none of that fibre's rays hit.
//
// Why a knot per measured fibre rather than the chord at each t_i: measured
// fibres that share a tendon end meet there, the chord between them vanishes
// and a per-t_i parameter would not increase; with the averaged knots the
// spline across meeting points is constant, and the surface fibres meet too.
//
// Not done: the deliverable connects the fibres "to their nearest tendons"
// using a measured tendon point cloud, which we do not have; the fibres end
// where the measured fibres end (extend them toward the attachments
// separately). The deliverable also notes that near the attachments the
// fibres are "wrong in principle": the inward rays there need not follow the
// muscle's architecture.

#include <vector>

#include "core/fibres/fibre_set.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

struct CadaverFibreOptions {
  // Segments per output fibre (>= 1): every fibre has segments + 1 points.
  int segments = 20;
  // Fibres on the surface, interpolated across the measured ones (>= 2; may
  // be fewer or more than the number measured). The first and last are the
  // outermost measured fibres, resampled and projected onto the surface.
  int surface_fibres = 9;
  // Fibres along each inward chord (>= 1): the surface fibre and
  // depth_layers - 1 more, the last on the opposite surface (see above). 1
  // casts no ray and returns the surface fibres only.
  int depth_layers = 9;
};

struct CadaverFibreResult {
  // surface_fibres * depth_layers fibres of segments + 1 points each (mm),
  // from origin to insertion; fibres[j * depth_layers + k] is layer k under
  // surface fibre j (k = 0: the surface fibre itself).
  std::vector<Fibre> fibres;
  // The surface_fibres interpolated surface fibres, in order across.
  std::vector<Fibre> surface;
  // Rays (out of surface_fibres * (segments + 1) when depth_layers > 1)
  // without an exit from the muscle; see the header comment.
  int rays_missed = 0;
};

// The CF decomposition of the muscle bounded by `surface`.
//   surface   closed, outward-oriented muscle surface: V #V by 3 (mm), F #F by 3
//   measured  >= 2 measured fibres, each >= 2 points (mm) on or near the surface
//             (the interpolated points are projected onto it), each from origin
//             to insertion, in order across the muscle (side by side)
// Throws InvalidInputError for an empty or invalid mesh, fewer than two
// measured fibres, a fibre with fewer than two points, non-finite points,
// repeated consecutive points, a fibre running the other way than the first
// (|o - o_0| + |i - i_0| > |o - i_0| + |i - o_0| for its origin o and
// insertion i, fibre 0's o_0 and i_0), two neighbouring fibres that
// coincide, options out of range, and when depth_layers > 1 and no ray at
// all leaves the muscle (the surface is open or oriented inward).
CadaverFibreResult cadaver_fibres(const mesh::IndexedMesh& surface,
                                  const std::vector<Fibre>& measured,
                                  const CadaverFibreOptions& options = {});

}  // namespace mmm::fibres

#pragma once
// MMSS: muscle fibres from a mass-spring system (a reference document's
// method). A fibre is a chain of particles, one per layer (a contour around
// the muscle), joined by "along" springs; within a layer the particles form a
// grid x grid square grid, each joined by an "across" spring to its four grid
// neighbours. The grid's border ring is pinned to the contour; the interior
// particles move, each within its layer's plane, until the system balances:
//
//   pin border particle (i, j) of every layer to the contour point at the
//     perimeter fraction of (i, j) / (grid - 1) on the unit square's boundary
//   start interior particles on the square's concentric rings, each mapped to
//     the contour scaled about its centroid
//   repeat: move the interior particles towards balance
//   until the largest move of an iteration is below the tolerance
//
// The springs have rest length zero (the along springs in the cross-
// sections' terms, see below), so the energy
//
//   E = across_stiffness / 2 * sum over 4-neighbours a, b in a layer |p_a - p_b|^2
//     + along_stiffness / 2 * sum over consecutive particles a, b of a fibre
//         r_a r_b |(p_a - c_a) / r_a - (p_b - c_b) / r_b|^2
//
// (c a layer's centroid, r the square root of its area; between layers of one
// size an along spring is a plain one after moving the layers onto one
// centroid) is quadratic, and its balance (zero gradient, interior particles
// kept in their layers' planes) is one sparse linear system: a discrete
// Laplace problem with two unknowns per interior particle, all layers at
// once. An iteration here is a Newton step on it: the particles' imbalance is
// solved for their moves by conjugate gradients, to 1e-12 of the imbalance,
// preconditioned with each fibre's chain of along springs (solved exactly).
// So the first iteration lands on the balance up to that and rounding, and
// the second confirms it by moving less than the tolerance (one iteration
// when the start is already in balance). The reference's particle-by-particle
// relaxation reaches the same, unique, balance only after many sweeps. Eigen's
// sparse LDLT of the whole system would be exact in one step too, but its
// fill made it 3 to 5 times slower at 16 x 16 fibres by 51 layers, and far
// slower beyond.
//
// Choices the reference leaves open:
// - A layer's plane passes through its contour's centroid (by arc length),
//   normal to its vector area (Newell): a layer is a slice, and a particle
//   free in 3D would drift off it wherever neighbouring layers are not
//   parallel. A plane section's border lies in that plane; a non-planar
//   contour (an iso-line) keeps its border on the contour and its interior
//   on the plane.
// - An along spring is relaxed when its particles hold the same place
//   relative to their cross-sections (offset from the centroid over the
//   size), not when they coincide. Springs between the particles themselves
//   pull a tapering or leaning muscle's interior sideways toward the
//   neighbouring layers' interior, and at an end layer (one along neighbour)
//   out through its contour: measured for a frustum of radius 20 to 8 mm
//   over 13 layers, leaning 0.1 mm per mm (along_stiffness 1), or upright
//   with along_stiffness 10. Relative along springs leave layers similar to
//   each other (cylinders, prisms, frusta, leaning or not) without along
//   force; they share out only the layers' differences of shape.
// - Across springs join the 4-neighbourhood only. With zero rest length a
//   diagonal spring does not resist shear as a real one would; it only
//   changes the weights of the Laplace stencil, and both stencils keep an
//   evenly spaced grid (a prism's) in balance.
// - The reference slices the muscle perpendicular to its medial axis; here
//   the caller's contours are the slices.

#include <vector>

#include "core/fibres/fibre_set.h"

namespace mmm::fibres {

struct MassSpringOptions {
  // grid x grid fibres (>= 3); the border ring of 4 (grid - 1) fibres lies on
  // the surface, the (grid - 2)^2 others inside.
  int grid = 9;
  // Stiffness of the springs between consecutive particles of a fibre (> 0).
  // Only its ratio to across_stiffness matters: the larger, the more each
  // layer's grid follows its neighbours' (relative to their size) rather than
  // its own contour.
  double along_stiffness = 1.0;
  // Stiffness of the springs between 4-neighbours in a layer's grid (> 0).
  double across_stiffness = 1.0;
  // Newton steps at most (>= 1); two suffice unless rounding is larger than
  // the tolerance.
  int max_iterations = 2000;
  // Stop when no particle moved this far (mm, > 0) in an iteration.
  double tolerance_mm = 1e-4;
};

struct MassSpringResult {
  // grid * grid fibres, each with one point per layer (layers.size() by 3,
  // mm); fibre (i, j) at index i * grid + j, i along u, j along v of the
  // unit square (fibre_set.h).
  std::vector<Fibre> fibres;
  int iterations = 0;
  double largest_move_mm = 0;  // of any particle in the last iteration
  bool converged = false;      // largest_move_mm < tolerance_mm
};

// Fibres through `layers`, one closed contour per fibre level from origin to
// insertion (>= 2 contours, each of >= 3 points enclosing some area),
// consistent as fibre_set.h says: point 0 on the same side of the muscle,
// counter-clockwise seen from the insertion end. Border fibre (i, j) passes
// through each contour at the same fraction of its perimeter (from point 0)
// as (i, j) / (grid - 1) has of the unit square's (from (1, 0.5),
// counter-clockwise). Throws InvalidInputError for bad options, too few
// layers or points, non-finite points, a contour without area, and contours
// that turn the other way (against each other, or clockwise seen from the
// insertion end); SolverError if the solve breaks down (non-finite moves).
MassSpringResult mass_spring_fibres(const std::vector<Contour>& layers,
                                    const MassSpringOptions& options = {});

}  // namespace mmm::fibres

#pragma once
// A muscle's surface patch from a few fibres (the second reference
// document): each fibre, a t-polynomial, sampled at n equidistant t; at each
// t, an interpolating cubic spline through the fibres' points (in fibre order,
// parameterised by chord length) sampled at m points; the grid triangulated.

#include <Eigen/Core>
#include <vector>

#include "core/fibres/t_polynomial.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

// `count` (>= 2) points along the interpolating C2 cubic spline through
// `points` (K >= 2 rows, x y z in the first three columns; opensim::SimmSpline
// per coordinate, so cubics are reproduced, not "natural" ends), at equal
// steps of its chord-length parameter (two points: the straight segment). Throws
// InvalidInputError for too few points, repeated consecutive points or
// non-finite values.
Eigen::MatrixXd cubic_spline(const Eigen::MatrixXd& points, int count);

// The patch through `fibres` (>= 2, each of at least three dimensions; the
// first three are used): `along` (>= 2) samples along each fibre, `across`
// (>= 2) across them. Vertex (i, j) is row i * across + j; an open surface
// of 2 (along - 1)(across - 1) triangles.
mesh::IndexedMesh fibre_surface_patch(const std::vector<TPolynomial>& fibres, int along,
                                      int across);

}  // namespace mmm::fibres

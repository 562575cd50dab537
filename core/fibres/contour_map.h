#pragma once
// Mapping the unit square onto muscle contours by mean value coordinates
// (Floater 2003; the 2-D case of Ju et al. 2005): a point of the square is
// a convex combination of the square's boundary points, with weights that
// depend smoothly on the point; the same weights applied to a contour's
// points (matched to the square's boundary by arc-length fraction, see
// fibre_set.h) give the corresponding point inside the contour. The weights
// depend only on the point in the square, so a template fibre's weights are
// computed once and reused for every contour and every frame.

#include <Eigen/Core>

#include "core/fibres/fibre_set.h"

namespace mmm::fibres {

// `count` points around the square's boundary at equal perimeter steps:
// point 0 at (1, 0.5), counter-clockwise. `count` must be a positive
// multiple of 8 (so the four corners are among them).
Eigen::MatrixX2d square_boundary(int count);

// Mean value weights (1 by count, non-negative, summing to 1) of (u, v) in
// [0, 1]^2 with respect to square_boundary(count). On the boundary they
// interpolate linearly between the two nearest boundary points. Throws
// InvalidInputError for a point outside the square or a bad count.
Eigen::RowVectorXd square_mean_value_weights(const Eigen::Vector2d& uv, int count);

// The loop made consistent (fibre_set.h): resampled to `count` points at
// equal arc-length steps, turning counter-clockwise about `axis` (reversed
// when its vector area points against it), point 0 where the half-line from
// the loop's centroid along `reference` (projected onto the loop's plane)
// leaves the loop (the outermost crossing). Throws InvalidInputError for
// fewer than three points, a loop of zero length or area, or a reference
// along the loop's normal.
Contour consistent_contour(const Eigen::MatrixX3d& loop, const Eigen::Vector3d& axis,
                           const Eigen::Vector3d& reference, int count);

// `contour` with its start moved along itself (a cyclic shift by a
// fractional number of its equal arc-length steps) to where it best matches
// `neighbour` (same point count): the shift minimising the summed squared
// distances between corresponding points, both loops centred on their mean.
// Chained from contour to contour, it keeps the start from jumping across a
// muscle whose cross-sections tilt or twist. Throws InvalidInputError for
// different point counts or fewer than three points.
Contour align_start(const Contour& contour, const Contour& neighbour);

}  // namespace mmm::fibres

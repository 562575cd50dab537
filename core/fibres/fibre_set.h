#pragma once
// Muscle fibres as polylines, and the contours the decomposition methods
// work through. Shared conventions of core/fibres/:
//
// - A fibre runs from the muscle's origin end to its insertion end; a method
//   asked for `segments` segments returns segments + 1 points per fibre.
// - A contour is a closed loop around the muscle at one level along it
//   (a plane section, an iso-line of a harmonic field): its points in order,
//   the last not repeating the first. Contours of one stack are "consistent":
//   point 0 of every contour lies on the same side of the muscle (the
//   stack's reference direction), and all turn the same way, counter-
//   clockwise seen from the insertion end looking back to the origin.
// - The unit square [0, 1]^2 is the cross-section of the fibre templates;
//   its boundary corresponds to a contour starting at (1, 0.5) (contour
//   point 0) and running counter-clockwise in (u, v).

#include <Eigen/Core>
#include <vector>

namespace mmm::fibres {

using Fibre = Eigen::MatrixX3d;    // points from origin to insertion (mm)
using Contour = Eigen::MatrixX3d;  // closed loop, last point != first (mm)

}  // namespace mmm::fibres

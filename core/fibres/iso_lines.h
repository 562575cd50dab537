#pragma once
// Level sets of a scalar field on a triangle mesh: where a per-vertex value,
// linear across each face, equals a given level. A plane section of a
// surface is the level set of the signed distance to the plane; the
// harmonic method slices a muscle by level sets of its harmonic field.

#include <Eigen/Core>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::fibres {

// One connected piece of a level set: its points (on mesh edges) in order,
// oriented so that, seen from outside an outward-oriented surface, the
// higher values lie on its left (a loop turns counter-clockwise about the
// direction in which the values grow).
// `closed`: the last point connects back to the first (the piece went
// around); open pieces end on the mesh's boundary or at a non-manifold edge.
struct IsoLine {
  Eigen::MatrixX3d points;
  bool closed = false;
};

// The level set {values == level} of `values` (one per vertex of `surface`).
// A vertex whose value is >= level counts as above, so a level set never
// passes exactly through a vertex and every crossing edge holds one point.
// Throws InvalidInputError when the sizes differ or a value or the level is
// not finite. O(#F).
std::vector<IsoLine> iso_lines(const mesh::IndexedMesh& surface, const Eigen::VectorXd& values,
                               double level);

// The vector area of a closed loop (Newell): normal to the plane that fits
// it best, counter-clockwise turning about it, of length the area of the
// loop's projection onto that plane (mm^2).
Eigen::Vector3d vector_area(const Eigen::MatrixX3d& loop);

// |vector_area| (mm^2).
double enclosed_area(const Eigen::MatrixX3d& loop);

// The closed piece with the largest enclosed_area; an empty matrix when no
// piece is closed.
Eigen::MatrixX3d largest_loop(const std::vector<IsoLine>& lines);

}  // namespace mmm::fibres

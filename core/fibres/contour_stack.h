#pragma once
// A stack of consistent contours from level sets of a per-vertex function:
// the largest closed loop at each level (iso_lines.h) made consistent
// (contour_map.h), gaps filled by interpolation between neighbours.

#include <Eigen/Core>
#include <vector>

#include "core/fibres/fibre_set.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

struct ContourStack {
  std::vector<Contour> contours;  // one per level
  int interpolated = 0;           // levels without a closed loop, filled in
};

// One contour per entry of `levels`. Loops keep the orientation iso_lines
// gives them (counter-clockwise about the direction in which `values` grow).
// The closed loop nearest the middle level starts on the side of
// `reference`; from it outward, each loop starts where it best matches its
// neighbour (contour_map.h, align_start), so starts do not jump between
// sides where tilted or non-planar loops see the reference differently. Throws InvalidInputError
// when fewer than two levels have a closed loop.
ContourStack contour_stack(const mesh::IndexedMesh& surface, const Eigen::VectorXd& values,
                           const std::vector<double>& levels, const Eigen::Vector3d& reference,
                           int contour_points);

}  // namespace mmm::fibres

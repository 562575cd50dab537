#pragma once
// The slicing decomposition (the Advanced Slicing Method of the first
// reference document, section 3.4.3): template fibres of the unit cube
// (fibre_templates.h) mapped into the muscle slice by slice.
//
// 1. The muscle's axes (decomposition.h): origin -> insertion, a reference
//    direction across.
// 2. Two cut planes across the axis through the innermost points of the
//    attachment areas (the paper's planes through the extreme attachment
//    landmarks), kept between 2 % and 35 % of the muscle's length from its
//    ends; segments + 1 planes between them, evenly spaced, each giving
//    the muscle's largest section contour, made consistent (contour_map.h).
//    A plane without a closed section gets the contour interpolated from
//    its neighbours.
// 3. Each template fibre mapped into the contours by mean value coordinates.
// 4. The fibre parts beyond the cut planes rebuilt: each end extended to
//    its own point of the attachment area (match_ends: fibres keep their
//    order over the area), smoothed, resampled to equal segments.

#include <vector>

#include "core/fibres/decomposition.h"
#include "core/fibres/fibre_set.h"

namespace mmm::fibres {

using SlicingResult = ContourFibres;

// The heights (along axes.axis, from axes.origin_centre) of the
// segments + 1 planes of step 2, and the height of every surface vertex.
struct SlicingPlanes {
  Eigen::VectorXd vertex_heights;
  std::vector<double> levels;
};
SlicingPlanes slicing_planes(const mesh::IndexedMesh& surface, const Attachments& attachments,
                             const MuscleAxes& axes, int segments);

// Throws InvalidInputError for bad options or attachments (decomposition.h)
// or when fewer than two planes have a closed section.
SlicingResult slicing_fibres(const mesh::IndexedMesh& surface, const Attachments& attachments,
                             const DecompositionOptions& options = {});

}  // namespace mmm::fibres

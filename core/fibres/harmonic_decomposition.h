#pragma once
// The harmonic decomposition (the Kukacka method of the first reference
// document, section 3.4.3): like the slicing decomposition, template fibres
// mapped contour by contour, but the contours are level sets of the
// muscle's harmonic field (harmonic_field.h) instead of planes: twisted,
// non-planar, and running into the attachment areas, so the fibres spread
// over the whole of each area. Levels from `end_level` to 1 - end_level,
// evenly spaced; the short gap to the attachment is bridged as in the
// slicing method.

#include <vector>

#include "core/fibres/decomposition.h"
#include "core/fibres/fibre_set.h"

namespace mmm::fibres {

using HarmonicResult = ContourFibres;

constexpr double kHarmonicEndLevel = 0.01;

// `field`: harmonic_field of this surface (or of the same mesh at rest: a
// wrapped muscle keeps its field). Throws InvalidInputError for bad options,
// a field of the wrong size or not finite, or fewer than two closed levels.
HarmonicResult harmonic_fibres(const mesh::IndexedMesh& surface, const Attachments& attachments,
                               const Eigen::VectorXd& field,
                               const DecompositionOptions& options = {});

}  // namespace mmm::fibres

#pragma once
// Fibres kept inside their muscle: a fibre point outside the surface (mean
// value maps of non-convex sections, end extensions across a thin sheet of
// muscle) is moved to the nearest surface point and `margin_mm` further in,
// along the normal of the face it lands on.

#include <vector>

#include "core/fibres/fibre_set.h"
#include "core/mesh/winding_number.h"

namespace mmm::fibres {

// Moves every point outside `inside` (winding number <= 1/2) of every fibre
// except the two ends, which are moved onto the surface (margin 0), since
// they belong on the attachment areas. Returns how many points moved.
int keep_inside(std::vector<Fibre>& fibres, const mesh::WindingNumber& inside, double margin_mm);

}  // namespace mmm::fibres

#pragma once
// A picture of a muscle with its fibres for people: the fibres as thin tubes
// in front of the far wall of the muscle (the faces turned away from the
// camera, so the near wall does not hide them), seen from the front and
// from the subject's right side by side.

#include <vector>

#include "core/fibres/fibre_set.h"
#include "core/image/image.h"
#include "core/mesh/mesh.h"

namespace mmm::nodes {

image::RgbImage8 fibre_picture(const mesh::IndexedMesh& muscle,
                               const std::vector<fibres::Fibre>& fibres, int width_px = 500);

}  // namespace mmm::nodes

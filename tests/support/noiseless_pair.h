#pragma once
// A noiseless calibrated biplanar pair of one closed surface (bone at
// image::kBoneMuPerMm in air), for the analytic outline-fitting tests.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/image/image.h"
#include "core/image/projection.h"
#include "core/mesh/mesh.h"

namespace mmm::test {

struct NoiselessPair {
  std::array<image::RadiographView, 2> views;
  std::vector<image::GrayImage16> images;  // one per view, in order
};

// Square field of `field_mm` around `isocentre`, detector pitch 0.5 mm.
NoiselessPair render_noiseless_pair(const mesh::IndexedMesh& surface,
                                    const Eigen::Vector3d& isocentre, double field_mm);

}  // namespace mmm::test

#include "tests/support/noiseless_pair.h"

#include "core/image/drr.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::test {

NoiselessPair render_noiseless_pair(const mesh::IndexedMesh& surface,
                                    const Eigen::Vector3d& isocentre, double field_mm) {
  image::BiplanarOptions geometry;
  geometry.isocentre_mm = isocentre;
  geometry.field_width_mm = field_mm;
  geometry.field_height_mm = field_mm;
  geometry.detector_pixel_pitch_mm = 0.5;
  NoiselessPair pair;
  pair.views = image::make_biplanar_views(geometry);
  const mesh::AabbTree tree(surface);
  const std::vector<image::AttenuatingMesh> meshes = {{&tree, image::kBoneMuPerMm}};
  image::RadiographOptions detector;
  detector.quantum_noise = false;
  for (const image::RadiographView& view : pair.views) {
    pair.images.push_back(image::to_radiograph(image::render_drr(view, meshes), detector));
  }
  return pair;
}

}  // namespace mmm::test

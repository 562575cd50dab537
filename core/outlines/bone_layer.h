#pragma once
// What some bones add to a radiograph, predicted from their surfaces, so that
// another bone can be fitted on the image with them taken out.
//
// A radiograph in mmm is linear in the line integral (drr.h): inside the
// limb a bone adds gain * L to the image, with L the length of the ray inside
// it (mm) and gain the image units per mm of bone over the tissue it replaces
// (what the thickness term estimates, thickness_term.h). Where bones overlap
// on the image, the outline of one runs across the other, and the thickness
// term cannot read one bone's brightness on rows the other crosses. With the
// neighbours already fitted, their share of the image is
//   layer(u, v) = sum_bones gain_b L_b(u, v)
// rendered over a region of the view (rays through the pixel centres, only
// on pixels the bone's projection covers). EdgeImage::without subtracts it.
//
// The layer is only as good as the neighbours' fit and their gains: a
// neighbour's surface 1 mm off leaves a thin rim of its edge in the image.

#include <Eigen/Core>
#include <vector>

#include "core/image/image.h"
#include "core/image/projection.h"
#include "core/mesh/aabb_tree.h"
#include "core/outlines/bone_cover.h"

namespace mmm::outlines {

struct LayerBone {
  const mesh::AabbTree* surface = nullptr;  // closed, outward-oriented (not owned)
  double gain = 0.0;                        // image units per mm of bone, in this view
};

struct BoneLayer {
  image::FloatImage values;                          // image units, the region's pixels
  Eigen::Vector2i origin = Eigen::Vector2i::Zero();  // the region's first pixel in the view
  int pixels_crossed = 0;                            // pixels with some bone
};

// The layer of `bones` over `region` of `view` (clipped to the image).
// Throws InvalidInputError for a null surface, a gain that is not finite or a
// view that fails validate_view.
BoneLayer render_bone_layer(const std::vector<LayerBone>& bones, const image::RadiographView& view,
                            const PixelRegion& region);

}  // namespace mmm::outlines

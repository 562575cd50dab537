#include "core/outlines/bone_layer.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/errors.h"
#include "core/image/drr.h"

namespace mmm::outlines {

BoneLayer render_bone_layer(const std::vector<LayerBone>& bones, const image::RadiographView& view,
                            const PixelRegion& region) {
  image::validate_view(view);
  for (const LayerBone& bone : bones) {
    if (bone.surface == nullptr) throw InvalidInputError("bone layer: a bone has no surface");
    if (!std::isfinite(bone.gain)) {
      throw InvalidInputError("bone layer: a bone's gain is not finite");
    }
  }
  const int x0 = std::clamp(region.x0, 0, view.width);
  const int y0 = std::clamp(region.y0, 0, view.height);
  const int x1 = std::clamp(region.x0 + region.width, 0, view.width);
  const int y1 = std::clamp(region.y0 + region.height, 0, view.height);
  BoneLayer layer;
  layer.origin = {x0, y0};
  layer.values = image::FloatImage(std::max(0, x1 - x0), std::max(0, y1 - y0));
  if (layer.values.empty()) return layer;
  std::vector<std::uint8_t> crossed(layer.values.sample_count(), 0);
  for (const LayerBone& bone : bones) {
    if (bone.gain == 0) continue;
    const BoneCover cover(bone.surface->mesh(), view);
    const PixelRegion box = cover.region();
    const std::array<image::AttenuatingMesh, 1> mesh = {
        image::AttenuatingMesh{bone.surface, bone.gain}};
    for (int y = std::max(y0, box.y0); y < std::min(y1, box.y0 + box.height); ++y) {
      for (int x = std::max(x0, box.x0); x < std::min(x1, box.x0 + box.width); ++x) {
        if (!cover.covered(x, y)) continue;
        const image::Ray ray = image::backproject(view, {x + 0.5, y + 0.5});
        const double value = image::line_integral(ray, mesh);
        if (value == 0) continue;
        const std::size_t k = layer.values.index(x - x0, y - y0);
        layer.values.pixels[k] += static_cast<float>(value);
        crossed[k] = 1;
      }
    }
  }
  layer.pixels_crossed = static_cast<int>(std::ranges::count(crossed, 1));
  return layer;
}

}  // namespace mmm::outlines

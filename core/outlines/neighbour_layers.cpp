#include "core/outlines/neighbour_layers.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace mmm::outlines {

NeighbourLayers::NeighbourLayers(
    const std::vector<std::pair<std::string, const BoneOutlineFit*>>& neighbours,
    const atlas::AtlasMeshes& meshes,
    std::vector<std::pair<std::string, const mesh::IndexedMesh*>> bones,
    const std::vector<image::RadiographView>& views)
    : bones_(std::move(bones)), views_(&views) {
  for (const auto& [name, fit] : neighbours) {
    Fitted item;
    item.name = name;
    item.tree = std::make_unique<mesh::AabbTree>(
        mesh::IndexedMesh{fit->vertices, meshes.at(name).at("full").F});
    item.gain.assign(views.size(), 0.0);
    for (std::size_t v = 0; v < views.size() && v < fit->views.size(); ++v) {
      item.gain[v] = std::max(0.0, fit->views[v].thickness_gain);
    }
    fitted_.push_back(std::move(item));
  }
  for (std::size_t v = 0; v < views.size(); ++v) {
    std::vector<double> measured;
    for (const Fitted& item : fitted_) {
      if (item.gain[v] > 0) measured.push_back(item.gain[v]);
    }
    if (measured.empty()) continue;
    const auto middle = measured.begin() + static_cast<std::ptrdiff_t>(measured.size() / 2);
    std::ranges::nth_element(measured, middle);
    for (Fitted& item : fitted_) {
      if (!(item.gain[v] > 0)) item.gain[v] = *middle;
    }
  }
}

void NeighbourLayers::fill(NeighbourViews& out, const std::string& bone,
                           const mesh::IndexedMesh& surface, const std::vector<FitView>& base,
                           double margin_mm) const {
  out.views = base;
  out.pixels_removed.assign(base.size(), 0);
  for (std::size_t v = 0; v < base.size(); ++v) {
    const image::RadiographView& view = (*views_)[v];
    std::vector<LayerBone> layer_bones;
    std::vector<std::string> removed;
    for (const Fitted& item : fitted_) {
      if (item.name == bone || !(item.gain[v] > 0)) continue;
      layer_bones.push_back({item.tree.get(), item.gain[v]});
      removed.push_back(item.name);
    }
    if (layer_bones.empty()) continue;
    PixelRegion region = BoneCover(surface, view).region();
    const int margin = static_cast<int>(std::ceil(margin_mm / view.pixel_spacing_mm));
    region.x0 -= margin;
    region.y0 -= margin;
    region.width += 2 * margin;
    region.height += 2 * margin;
    const BoneLayer layer = render_bone_layer(layer_bones, view, region);
    if (layer.pixels_crossed == 0) continue;
    out.pixels_removed[v] = layer.pixels_crossed;
    // One derived image per distinct stage image.
    std::map<const EdgeImage*, const EdgeImage*> derived;
    for (const EdgeImage*& edges : out.views[v].edges) {
      auto found = derived.find(edges);
      if (found == derived.end()) {
        out.edges.push_back(
            std::make_unique<EdgeImage>(edges->without(layer.values, layer.origin)));
        found = derived.emplace(edges, out.edges.back().get()).first;
      }
      edges = found->second;
    }
    // The bones' cover without the neighbours taken out.
    if (base[v].cover != nullptr) {
      std::vector<const mesh::IndexedMesh*> kept;
      for (const auto& [name, mesh] : bones_) {
        if (std::ranges::find(removed, name) == removed.end()) kept.push_back(mesh);
      }
      out.covers.push_back(std::make_unique<std::vector<std::uint8_t>>(count_cover(kept, view)));
      out.views[v].cover = out.covers.back().get();
    }
  }
}

}  // namespace mmm::outlines

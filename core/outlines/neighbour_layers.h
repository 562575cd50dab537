#pragma once
// The radiographs a bone is fitted on after its neighbours: each view's
// images less the fitted neighbours' share of them (bone_layer.h), and the
// bones' cover without those neighbours, so that the thickness term reads
// the rows they cross (thickness_term.h).
//
// A neighbour's gain in a view is the one its thickness term measured there;
// a neighbour fitted without the term (the hip bones) takes the median of the
// others' gains in that view. With no gain measured in a view, nothing is
// taken out of it.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_meshes.h"
#include "core/mesh/aabb_tree.h"
#include "core/outlines/bone_layer.h"
#include "core/outlines/outline_fit.h"

namespace mmm::outlines {

// One bone's views with its neighbours taken out. Owns the images and covers
// its views point to (not copyable or movable for that reason).
struct NeighbourViews {
  NeighbourViews() = default;
  NeighbourViews(const NeighbourViews&) = delete;
  NeighbourViews& operator=(const NeighbourViews&) = delete;

  std::vector<FitView> views;
  std::vector<int> pixels_removed;  // per view: pixels where some neighbour was taken out
  std::vector<std::unique_ptr<EdgeImage>> edges;
  std::vector<std::unique_ptr<std::vector<std::uint8_t>>> covers;
};

class NeighbourLayers {
 public:
  // `neighbours`: the fitted bones (their names and fits); `bones`: every bone
  // of the atlas at the level the covers are drawn from (name and surface).
  NeighbourLayers(const std::vector<std::pair<std::string, const BoneOutlineFit*>>& neighbours,
                  const atlas::AtlasMeshes& meshes,
                  std::vector<std::pair<std::string, const mesh::IndexedMesh*>> bones,
                  const std::vector<image::RadiographView>& views);

  // `base`: the views the bone would be fitted on; `surface`: its start
  // surface (where to render the layer: its projection and `margin_mm`
  // around it, at the isocentre).
  void fill(NeighbourViews& out, const std::string& bone, const mesh::IndexedMesh& surface,
            const std::vector<FitView>& base, double margin_mm) const;

 private:
  struct Fitted {
    std::string name;
    std::unique_ptr<mesh::AabbTree> tree;
    std::vector<double> gain;  // per view; 0: not taken out
  };
  std::vector<Fitted> fitted_;
  std::vector<std::pair<std::string, const mesh::IndexedMesh*>> bones_;
  const std::vector<image::RadiographView>* views_ = nullptr;
};

}  // namespace mmm::outlines

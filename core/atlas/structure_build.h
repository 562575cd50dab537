#pragma once
// The atlas build's cartilages and ligaments (atlas.h, Structure): each
// surface is read in the atlas frame, checked to be a closed outward
// surface, and measured against the bone(s) it belongs to. A structure that
// does not reach its bone would float away with it: the build refuses it.

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_recipe.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

struct StructureBuildReport {
  std::string name;
  std::string kind;  // "cartilage" or "ligament"
  int faces = 0;
  bool watertight = false;
  double volume_mm3 = 0.0;
  // Per bone it belongs to: the gap between the surfaces (0 when they
  // overlap) and how deep they overlap (a cartilage lies partly inside a CT
  // bone segmented with its cartilage).
  std::vector<std::pair<std::string, double>> gap_mm;
  std::vector<std::pair<std::string, double>> overlap_mm;
};

struct StructureBuildOptions {
  double max_gap_mm = 3.0;  // farther from one of its bones: the build fails
};

// Reads every structure of `recipe` (`read` resolves and reads a recipe data
// path, naming the field in its errors), adds it to `atlas` (and its region)
// and its full-resolution surface to `surfaces`. Throws InvalidInputError
// naming the structure when its surface is empty, not closed, inside out or
// farther than `max_gap_mm` from one of its bones.
std::vector<StructureBuildReport> add_structures(
    const AtlasRecipe& recipe,
    const std::function<mesh::IndexedMesh(const std::string& file, const std::string& field)>& read,
    const std::map<std::string, mesh::IndexedMesh>& bones, const StructureBuildOptions& options,
    Atlas& atlas, std::map<std::string, mesh::IndexedMesh>& surfaces);

}  // namespace mmm::atlas

#pragma once
// The atlas build's wrap-surface step: every wrap surface of the recipe
// fitted to its bone (wrap_surface_fit.h), given to the muscles of the lines
// it names (their `wrap_obstacles`, in recipe order), and the path points it
// replaces left out of those lines.

#include <map>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_recipe.h"
#include "core/atlas/wrap_surface_fit.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

// Fits `recipe.wrap_surfaces` to `bone_meshes` (atlas frame, rest) and adds
// them to `atlas`. Throws InvalidInputError naming the surface when its joint,
// point, line or a replaced point does not exist, or its region is empty.
std::vector<WrapSurfaceFitReport> add_wrap_surfaces(
    const AtlasRecipe& recipe, const std::map<std::string, mesh::IndexedMesh>& bone_meshes,
    Atlas& atlas);

// The unit atlas direction a recipe side names (anterior = +y, superior =
// +z, right = +x in the atlas frame).
Eigen::Vector3d side_direction(const std::string& side);

}  // namespace mmm::atlas

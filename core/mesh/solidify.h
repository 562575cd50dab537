#pragma once
// A clean closed surface for a broken one: the boundary of the solid a mesh
// encloses, even when the mesh has holes, non-manifold edges or stray
// pieces (OpenSim's gait2392 pelvis has all three).
//
//   w(x) = |generalized winding number| of the input (Jacobson et al. 2013;
//          absolute, so pieces oriented inwards count as solid too),
//          sampled on a regular grid of spacing h around the mesh
//   surface = the level set w = 1/2, extracted by marching tetrahedra
//             (six tetrahedra per cube around its main diagonal, the same
//             split in every cube, so neighbouring cubes agree and the
//             result is a closed 2-manifold), each triangle oriented from
//             the inside (w > 1/2) to the outside.
//
// Features smaller than h are lost and sharp edges are rounded at that
// scale; remesh the result (remesh_uniform) for well-shaped triangles.

#include "core/mesh/mesh.h"

namespace mmm::mesh {

struct SolidifyOptions {
  double grid_spacing_mm = 1.5;  // h, > 0
  int padding_cells = 2;         // empty cells around the bounding box, >= 1
};

// Throws InvalidInputError for an empty or invalid mesh, a non-positive
// spacing, padding_cells < 1, or a grid above 50 million points (choose a larger spacing).
IndexedMesh solidify(const IndexedMesh& mesh, const SolidifyOptions& options = {});

}  // namespace mmm::mesh

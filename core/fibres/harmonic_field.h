#pragma once
// The harmonic scalar field of a muscle surface (the Kukacka decomposition
// of the first reference document, after Dong et al. 2005): the function
// that is 0 on the muscle's origin attachment, 1 on its insertion attachment
// and harmonic in between (cotangent Laplacian zero at every other vertex).
// Its level sets are the twisted, non-planar "slices" of the harmonic
// decomposition. It depends only on the mesh and the attachments, so it is
// computed once per muscle and reused for every frame of a wrapped muscle
// (same vertices, new positions).

#include <Eigen/Core>
#include <vector>

#include "core/fibres/end_patches.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

// The field (one value per vertex, in [0, 1] up to the cotangent weights'
// discrete maximum principle), 0 on ends.origin and 1 on ends.insertion
// (end_patches.h). Throws InvalidInputError for an empty
// attachment set or overlapping ones, SolverError when the system cannot be
// factored (a piece of the surface touching neither attachment).
Eigen::VectorXd harmonic_field(const mesh::IndexedMesh& surface, const EndPatches& ends);

}  // namespace mmm::fibres

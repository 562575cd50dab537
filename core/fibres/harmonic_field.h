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

#include "core/fibres/decomposition.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

// The surface vertices on each attachment area: those within `distance_mm`
// of one of its points and nearer to it than to the other area; when fewer
// than 3 (a muscle surface that stops short of its bone), the 3 nearest to
// the area's points that the other area does not hold. Throws
// InvalidInputError when an attachment has no points.
struct AttachmentVertices {
  std::vector<int> origin;
  std::vector<int> insertion;
};
AttachmentVertices attachment_vertices(const mesh::IndexedMesh& surface,
                                       const Attachments& attachments, double distance_mm = 3.0);

// The field (one value per vertex, in [0, 1] up to the cotangent weights'
// discrete maximum principle). Throws InvalidInputError for an empty
// attachment set or overlapping ones, SolverError when the system cannot be
// factored (a piece of the surface touching neither attachment).
Eigen::VectorXd harmonic_field(const mesh::IndexedMesh& surface,
                               const AttachmentVertices& attachments);

}  // namespace mmm::fibres

#pragma once
// Wavefront OBJ surfaces: the geometry subset (v and f statements).

#include <filesystem>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

// Reads `v x y z` and `f ...` statements. Face corners may be written as v,
// v/vt, v/vt/vn or v//vn; indices are 1-based, negative ones count back from
// the last vertex defined so far (-1 is the latest). Polygons are
// fan-triangulated. vt, vn, g, o, s, usemtl, mtllib, l, comments and unknown
// statements are ignored.
//
// Returns
//   V  #V by 3 vertex positions in file order (file units)
//   F  #F by 3 0-based indices into V
// Throws IoError (path first) when the file is missing or empty, a vertex has
// fewer than 3 numbers or a non-finite one, a face has fewer than 3 corners or
// refers to a vertex that is not defined ("line L: face refers to vertex I but
// only N vertices are defined"), or there is no face at all.
IndexedMesh read_obj(const std::filesystem::path& path);

// Writes v and f statements (shortest round-trip text of every coordinate, so
// read_obj gives back exactly V and F), atomically (temporary sibling + rename).
// Throws InvalidInputError for a mesh with no faces, a non-finite coordinate or
// an index out of range; IoError when the file cannot be written.
void write_obj(const IndexedMesh& mesh, const std::filesystem::path& path);

}  // namespace mmm::mesh

#pragma once
// Geomview Object File Format (OFF) surfaces, ASCII.

#include <filesystem>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

// Reads an ASCII OFF file: the (optional) keyword OFF (or a COFF/NOFF/STOFF
// variant, whose extra per-vertex values are skipped), the counts line
// "#vertices #faces [#edges]", one vertex per line (x y z, further values
// ignored) and one face per line (n i0 ... in-1, 0-based, trailing colour
// values ignored). '#' starts a comment. Polygons are fan-triangulated.
//
// Returns
//   V  #V by 3 vertex positions in file order (file units)
//   F  #F by 3 0-based indices into V
// Throws IoError (path first; syntax problems with their line number) for a
// missing or empty file, binary or 4D/nD OFF, malformed counts, a missing or
// non-finite coordinate, a face with fewer than 3 corners or an index out of
// range, a file that ends early, or no faces.
IndexedMesh read_off(const std::filesystem::path& path);

// Writes "OFF", the counts and the vertices (shortest round-trip text, so
// read_off gives back exactly V and F) and triangles, atomically.
// Throws InvalidInputError for a mesh with no faces, a non-finite coordinate or
// an index out of range; IoError when the file cannot be written.
void write_off(const IndexedMesh& mesh, const std::filesystem::path& path);

}  // namespace mmm::mesh

#pragma once
// STL (stereolithography) surfaces, binary and ASCII.
//
// STL stores every triangle with its own three corners. The reader welds
// corners with exactly equal coordinates into shared vertices so the result
// has the topology the kernels need; the writer stores float32 coordinates
// (binary) or their shortest float text (ASCII), with facet normals computed
// from the corner order.

#include <filesystem>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

// Reads a binary or ASCII STL file.
//
// Format detection: binary when the file size is exactly 84 + 50 * N, N being
// the triangle count stored after the 80-byte header (even when the header
// starts with "solid", as many exporters write); otherwise ASCII when the file
// starts with "solid"; otherwise a truncated or padded binary file (IoError
// with the announced count, the expected and the actual size).
//
// Returns
//   V  #V by 3 welded vertex positions in first-occurrence order (file units)
//   F  #F by 3 indices into V, in file order (facets with more than 3 corners,
//      a non-standard ASCII extension, are fan-triangulated)
// Throws IoError (path first) when the file is missing, empty, truncated, has
// a NaN/inf coordinate ("triangle K vertex J has a non-finite coordinate",
// K and J 0-based), an ASCII syntax error (with its line number) or no
// triangles.
IndexedMesh read_stl(const std::filesystem::path& path);

struct StlWriteOptions {
  // false (default): binary STL (80-byte header, float32 coordinates).
  // true: ASCII STL ("solid ... endsolid"), coordinates as the shortest text
  // of their float32 value so binary and ASCII files hold the same numbers.
  bool ascii = false;
};

// Writes mesh (V in file units, F counter-clockwise seen from outside) as STL,
// atomically (temporary sibling + rename). Coordinates are rounded to float32.
// Throws InvalidInputError for a mesh with no faces, a non-finite coordinate
// or an index out of range; IoError when the file cannot be written.
void write_stl(const IndexedMesh& mesh, const std::filesystem::path& path,
               const StlWriteOptions& options = {});

}  // namespace mmm::mesh

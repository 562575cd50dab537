#pragma once
// Stanford PLY surfaces: ascii, binary_little_endian and binary_big_endian.

#include <filesystem>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

// Reads a PLY 1.0 file.
//  - element vertex: properties x, y, z of any scalar type (char/int8, uchar/
//    uint8, short/int16, ushort/uint16, int/int32, uint/uint32, float/float32,
//    double/float64); other properties, scalar or list, are skipped by size.
//  - element face: a list property named vertex_indices or vertex_index, any
//    count and index types; polygons are fan-triangulated; other properties
//    are skipped.
//  - other elements (edge, material, ...) are skipped.
//
// Returns
//   V  #V by 3 vertex positions in file order (file units)
//   F  #F by 3 0-based indices into V
// Throws IoError (path first) for a missing or empty file, a malformed or
// unsupported header (with its line number), truncated binary data or ASCII
// data that ends early or is not a number (with the element and property and,
// for ASCII, the line), a non-finite coordinate, a face with fewer than 3
// corners or an index out of range, or no faces.
IndexedMesh read_ply(const std::filesystem::path& path);

struct PlyWriteOptions {
  // false (default): binary_little_endian; true: ascii. Both store x, y, z as
  // double and faces as "list uchar int vertex_indices", so read_ply gives back
  // exactly V and F.
  bool ascii = false;
};

// Writes mesh as PLY, atomically (temporary sibling + rename).
// Throws InvalidInputError for a mesh with no faces, a non-finite coordinate or
// an index out of range; IoError when the file cannot be written.
void write_ply(const IndexedMesh& mesh, const std::filesystem::path& path,
               const PlyWriteOptions& options = {});

}  // namespace mmm::mesh

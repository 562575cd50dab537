#pragma once
// Reading and writing surface meshes by file extension: the one entry point
// nodes and the command line use. Each format has its own header (stl.h,
// obj.h, ply.h, off.h, vtp.h) for format-specific options.
//
// Every reader first checks the path (IoError "no such file", "is a
// directory, not a mesh file", "file is empty", or unreadable), then parses
// the whole file and validates the result: finite coordinates, indices in
// range, at least one triangle ("contains no triangles"). Problems are
// reported with the path and the element (triangle number, line number).
// Polygons with more than 3 corners are fan-triangulated (right for the convex
// polygons these files hold). Degenerate faces (a repeated index) are kept:
// the mesh checker reports them; readers never drop data silently.

#include <filesystem>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

enum class MeshFormat { kStl, kObj, kPly, kOff, kVtp };

// Format named by the file extension, case-insensitive (.stl .obj .ply .off
// .vtp). Throws IoError listing the supported extensions for any other.
MeshFormat format_from_extension(const std::filesystem::path& path);

// Reads the mesh at `path` with the reader of its extension.
//   V  #V by 3 vertex positions (file units: mm for the VHF STLs, m for the
//      OpenSim .vtp geometry)
//   F  #F by 3 0-based indices into V
// Throws IoError (see above and the per-format headers).
IndexedMesh read_mesh(const std::filesystem::path& path);

struct WriteOptions {
  // STL and PLY: ASCII instead of binary. Ignored by OBJ, OFF (always ASCII)
  // and VTP (always ASCII data arrays).
  bool ascii = false;
};

// Writes mesh in the format of the extension of `path`. Creates nothing but
// the file (the folder must exist): the bytes go to a temporary sibling that
// is then renamed, so a crash never leaves a half-written file.
// Throws IoError for an unknown extension or a failed write, and
// InvalidInputError for a mesh with no faces, a non-finite coordinate or an
// index out of range.
void write_mesh(const IndexedMesh& mesh, const std::filesystem::path& path,
                const WriteOptions& options = {});

}  // namespace mmm::mesh

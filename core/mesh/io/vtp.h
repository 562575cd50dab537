#pragma once
// VTK XML PolyData (.vtp) surfaces with ASCII data arrays: the format of the
// OpenSim geometry files and the one ParaView opens with per-vertex and
// per-triangle scalar fields (distances, strains, labels) for inspection.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::mesh {

// Reads the <Piece>s of a <VTKFile type="PolyData">: the Points DataArray
// (NumberOfComponents 3, Float32 or Float64, format="ascii"), Polys
// (connectivity + offsets; polygons fan-triangulated) and Strips (triangle
// strips, split keeping a consistent orientation). Verts and Lines are not
// surface cells and are ignored; point and cell data arrays are not read.
// Pieces are concatenated (their point indices shifted). The file header's
// compressor attribute is irrelevant to ASCII arrays and is ignored.
//
// Returns
//   V  #V by 3 point positions in file order (file units; OpenSim uses metres)
//   F  #F by 3 0-based indices into V
// Throws IoError (path first) for a missing or empty file, malformed XML (with
// the line), a file that is not PolyData, a DataArray stored as
// format="binary" or "appended" (only ASCII VTP is read: re-save with the
// ASCII data mode), counts that disagree with NumberOfPoints / NumberOfPolys /
// NumberOfStrips, a non-finite coordinate, an index out of range, a cell with
// fewer than 3 points, or no triangles.
IndexedMesh read_vtp(const std::filesystem::path& path);

// Named scalar fields written beside the surface.
//   point_scalars  (name, values) pairs, each with #V values (one per vertex)
//   cell_scalars   (name, values) pairs, each with #F values (one per triangle)
// Names must be non-empty and unique within their list; values finite.
// The first point array is marked as the active Scalars.
struct VtpArrays {
  std::vector<std::pair<std::string, Eigen::VectorXd>> point_scalars;
  std::vector<std::pair<std::string, Eigen::VectorXd>> cell_scalars;
};

// Writes one Piece with ASCII Float64 points (shortest round-trip text: full
// precision), Int64 connectivity/offsets and the scalar arrays as PointData /
// CellData, under the header
//   <VTKFile type="PolyData" version="1.0" byte_order="LittleEndian"
//   header_type="UInt64">
// atomically (temporary sibling + rename). read_vtp gives back exactly V, F.
// Throws InvalidInputError for a mesh with no faces, a non-finite coordinate,
// an index out of range, or an array whose length, name or values are wrong;
// IoError when the file cannot be written.
void write_vtp(const IndexedMesh& mesh, const std::filesystem::path& path,
               const VtpArrays& arrays = {});

}  // namespace mmm::mesh

#pragma once
// Open polylines (muscle action lines, muscle fibres) as VTK XML PolyData
// (.vtp) <Lines> cells with optional per-point and per-line scalars, for
// ParaView beside the bone and muscle surfaces written by write_vtp.

#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "core/mesh/io/vtp.h"

namespace mmm::mesh {

// Several open polylines sharing one point list.
//   points  #P by 3 point positions (mm)
//   lines   #L polylines, each a list of >= 2 indices into points, in order
//           along the line. A point may be shared by several lines; points
//           used by no line are kept (and written).
struct Polylines {
  Eigen::MatrixX3d points;
  std::vector<std::vector<int>> lines;
};

// Writes one Piece with ASCII Float64 points (shortest round-trip text), one
// <Lines> cell per polyline (Int64 connectivity + offsets) and the scalar
// arrays as PointData / CellData, under the same header as write_vtp,
// atomically (temporary sibling + rename). read_vtp_polylines gives back
// exactly points and lines.
//   arrays.point_scalars  each with #P values (one per point)
//   arrays.cell_scalars   each with #L values (one per line)
// Throws InvalidInputError ("cannot write <path>: ...") when there is no line,
// a line has fewer than 2 points or an index outside [0, #P), a coordinate is
// not finite, or an array's length, name or values are wrong; IoError when the
// file cannot be written.
void write_vtp_polylines(const Polylines& polylines, const std::filesystem::path& path,
                         const VtpArrays& arrays = {});

// Reads the <Lines> cells (connectivity + offsets) and Points of every
// <Piece> of an ASCII <VTKFile type="PolyData">; pieces are concatenated
// (their point indices shifted). Verts, Polys and Strips are ignored, as are
// point and cell data arrays.
// Throws IoError (path first) for the same file problems as read_vtp (missing
// or empty file, malformed XML, not PolyData, binary/appended DataArrays,
// counts that disagree, non-finite coordinates, indices out of range), for a
// line with fewer than 2 points, and for a file without any line (a surface:
// read it with read_vtp).
Polylines read_vtp_polylines(const std::filesystem::path& path);

}  // namespace mmm::mesh

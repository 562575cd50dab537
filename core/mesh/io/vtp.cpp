#include "core/mesh/io/vtp.h"

#include <tinyxml2.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/mesh/io/io_common.h"
#include "core/mesh/io/vtp_common.h"

namespace mmm::mesh {

namespace {

// Triangle strip p0 p1 p2 p3 ...: triangles (p0 p1 p2), (p2 p1 p3), (p2 p3 p4), ...
// swapping the first two corners of every odd triangle keeps the orientation.
void append_strip(std::span<const int> strip, std::vector<int>& triangles) {
  for (std::size_t j = 0; j + 2 < strip.size(); ++j) {
    const bool odd = (j % 2) == 1;
    triangles.push_back(odd ? strip[j + 1] : strip[j]);
    triangles.push_back(odd ? strip[j] : strip[j + 1]);
    triangles.push_back(strip[j + 2]);
  }
}

enum class CellKind { kPolygon, kStrip };

// A polygon or a strip needs at least one triangle's worth of corners.
constexpr int kMinCorners = 3;

// Triangulates every cell of a Polys (fan) or Strips section.
void append_triangles(const vtk_detail::Cells& cells, CellKind kind, std::vector<int>& triangles) {
  const std::span<const int> indices(cells.indices);
  std::size_t start = 0;
  for (const std::size_t end : cells.ends) {
    const std::span<const int> cell = indices.subspan(start, end - start);
    if (kind == CellKind::kStrip) {
      append_strip(cell, triangles);
    } else {
      io_detail::append_fan(cell, triangles);
    }
    start = end;
  }
}

}  // namespace

IndexedMesh read_vtp(const std::filesystem::path& path) {
  tinyxml2::XMLDocument document;
  const tinyxml2::XMLElement& root = vtk_detail::load_vtk_file(
      path, document, "PolyData", "only PolyData (.vtp) is read as a surface");
  std::vector<double> coordinates;
  std::vector<int> triangles;
  int piece_number = 0;
  for (const tinyxml2::XMLElement* piece : vtk_detail::poly_data_pieces(path, root)) {
    const std::string label = "Piece " + std::to_string(piece_number++);
    const std::int64_t num_points =
        vtk_detail::count_attribute(path, *piece, "NumberOfPoints", true);
    const std::int64_t num_polys =
        vtk_detail::count_attribute(path, *piece, "NumberOfPolys", false);
    const std::int64_t num_strips =
        vtk_detail::count_attribute(path, *piece, "NumberOfStrips", false);
    const auto base = static_cast<std::int64_t>(coordinates.size() / 3);
    vtk_detail::read_points(path, *piece, num_points, label, coordinates);
    append_triangles(vtk_detail::read_cells(path, *piece, "Polys", num_polys, num_points, base,
                                            kMinCorners, label),
                     CellKind::kPolygon, triangles);
    append_triangles(vtk_detail::read_cells(path, *piece, "Strips", num_strips, num_points, base,
                                            kMinCorners, label),
                     CellKind::kStrip, triangles);
  }
  return io_detail::assemble_mesh(path, coordinates, triangles);
}

void write_vtp(const IndexedMesh& mesh, const std::filesystem::path& path,
               const VtpArrays& arrays) {
  io_detail::check_mesh_for_writing(mesh, path);
  vtk_detail::check_arrays(arrays.point_scalars, mesh.V.rows(),
                           {"point", "the mesh has", "vertex", "vertices"}, path);
  vtk_detail::check_arrays(arrays.cell_scalars, mesh.F.rows(),
                           {"cell", "the mesh has", "triangle", "triangles"}, path);

  std::string out;
  out.reserve(static_cast<std::size_t>(mesh.V.rows()) * 64 +
              static_cast<std::size_t>(mesh.F.rows()) * 40 + 1024);
  vtk_detail::append_header(out);
  vtk_detail::append_piece_start(out, mesh.V.rows(), 0, mesh.F.rows());
  vtk_detail::append_scalar_arrays(out, "PointData", arrays.point_scalars);
  vtk_detail::append_scalar_arrays(out, "CellData", arrays.cell_scalars);
  vtk_detail::append_points(out, mesh.V);

  out +=
      "      <Polys>\n"
      "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    out += "          ";
    for (Eigen::Index k = 0; k < 3; ++k) {
      if (k > 0) out += ' ';
      io_detail::append_number(out, static_cast<std::int64_t>(mesh.F(f, k)));
    }
    out += '\n';
  }
  out +=
      "        </DataArray>\n"
      "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  std::vector<std::int64_t> offsets;
  offsets.reserve(static_cast<std::size_t>(mesh.F.rows()));
  for (Eigen::Index f = 1; f <= mesh.F.rows(); ++f) offsets.push_back(3 * std::int64_t{f});
  vtk_detail::append_wrapped_integers(out, offsets, 10);
  out +=
      "        </DataArray>\n"
      "      </Polys>\n";
  vtk_detail::append_footer(out);
  io_detail::write_file_atomically(path, out);
}

}  // namespace mmm::mesh

#include "core/mesh/io/vtp_polylines.h"

#include <tinyxml2.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/errors.h"
#include "core/mesh/io/io_common.h"
#include "core/mesh/io/vtp_common.h"

namespace mmm::mesh {

namespace {

void check_polylines_for_writing(const Polylines& polylines, const std::filesystem::path& path) {
  const std::string where = "cannot write " + path.string() + ": ";
  if (polylines.lines.empty()) {
    throw InvalidInputError(where + "there are no polylines (a polyline file holds at least one)");
  }
  const Eigen::MatrixX3d& points = polylines.points;
  for (Eigen::Index p = 0; p < points.rows(); ++p) {
    if (!points.row(p).allFinite()) {
      throw InvalidInputError(where + "point " + std::to_string(p) +
                              " has a non-finite coordinate (NaN or inf)");
    }
  }
  for (std::size_t l = 0; l < polylines.lines.size(); ++l) {
    const std::vector<int>& line = polylines.lines[l];
    if (line.size() < 2) {
      throw InvalidInputError(where + "line " + std::to_string(l) + " has " +
                              std::to_string(line.size()) +
                              " point(s); a polyline needs at least 2");
    }
    for (const int index : line) {
      if (index < 0 || index >= points.rows()) {
        throw InvalidInputError(where + "line " + std::to_string(l) + " refers to point " +
                                std::to_string(index) + " but there are " +
                                std::to_string(points.rows()) + " points");
      }
    }
  }
}

// One text line per polyline: a fibre reads as one row of the file.
void append_lines(std::string& out, const std::vector<std::vector<int>>& lines) {
  out +=
      "      <Lines>\n"
      "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  std::vector<std::int64_t> offsets;
  offsets.reserve(lines.size());
  std::int64_t end = 0;
  for (const std::vector<int>& line : lines) {
    out += "          ";
    for (std::size_t k = 0; k < line.size(); ++k) {
      if (k > 0) out += ' ';
      io_detail::append_number(out, static_cast<std::int64_t>(line[k]));
    }
    out += '\n';
    end += static_cast<std::int64_t>(line.size());
    offsets.push_back(end);
  }
  out +=
      "        </DataArray>\n"
      "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  vtk_detail::append_wrapped_integers(out, offsets, 10);
  out +=
      "        </DataArray>\n"
      "      </Lines>\n";
}

}  // namespace

void write_vtp_polylines(const Polylines& polylines, const std::filesystem::path& path,
                         const VtpArrays& arrays) {
  check_polylines_for_writing(polylines, path);
  const auto num_lines = static_cast<Eigen::Index>(polylines.lines.size());
  vtk_detail::check_arrays(arrays.point_scalars, polylines.points.rows(),
                           {"point", "the polylines have", "point", "points"}, path);
  vtk_detail::check_arrays(arrays.cell_scalars, num_lines,
                           {"cell", "the polylines have", "line", "lines"}, path);

  std::string out;
  out.reserve(static_cast<std::size_t>(polylines.points.rows()) * 72 + 1024);
  vtk_detail::append_header(out);
  vtk_detail::append_piece_start(out, polylines.points.rows(), num_lines, 0);
  vtk_detail::append_scalar_arrays(out, "PointData", arrays.point_scalars);
  vtk_detail::append_scalar_arrays(out, "CellData", arrays.cell_scalars);
  vtk_detail::append_points(out, polylines.points);
  append_lines(out, polylines.lines);
  vtk_detail::append_footer(out);
  io_detail::write_file_atomically(path, out);
}

Polylines read_vtp_polylines(const std::filesystem::path& path) {
  tinyxml2::XMLDocument document;
  const tinyxml2::XMLElement& root =
      vtk_detail::load_vtk_file(path, document, "PolyData", "only PolyData (.vtp) holds polylines");
  std::vector<double> coordinates;
  Polylines polylines;
  int piece_number = 0;
  for (const tinyxml2::XMLElement* piece : vtk_detail::poly_data_pieces(path, root)) {
    const std::string label = "Piece " + std::to_string(piece_number++);
    const std::int64_t num_points =
        vtk_detail::count_attribute(path, *piece, "NumberOfPoints", true);
    const std::int64_t num_lines =
        vtk_detail::count_attribute(path, *piece, "NumberOfLines", false);
    const auto base = static_cast<std::int64_t>(coordinates.size() / 3);
    vtk_detail::read_points(path, *piece, num_points, label, coordinates);
    constexpr int kMinLinePoints = 2;
    const vtk_detail::Cells cells = vtk_detail::read_cells(path, *piece, "Lines", num_lines,
                                                           num_points, base, kMinLinePoints, label);
    std::size_t start = 0;
    for (const std::size_t end : cells.ends) {
      polylines.lines.emplace_back(cells.indices.begin() + static_cast<std::ptrdiff_t>(start),
                                   cells.indices.begin() + static_cast<std::ptrdiff_t>(end));
      start = end;
    }
  }
  if (polylines.lines.empty()) {
    throw IoError(path,
                  "contains no polylines (no <Lines> cells; a surface? read it with "
                  "read_vtp)");
  }
  using RowMajorPoints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  polylines.points = Eigen::Map<const RowMajorPoints>(
      coordinates.data(), static_cast<Eigen::Index>(coordinates.size() / 3), 3);
  return polylines;
}

}  // namespace mmm::mesh

#pragma once
// Pieces shared by the VTK XML readers and writers of core/mesh/io/ (vtp.cpp,
// vtp_polylines.cpp, pvd.cpp): loading and checking a <VTKFile>, the ASCII
// DataArrays of a PolyData <Piece> (Points and connectivity + offsets cell
// sections), and on the writing side the header, points, scalar arrays and
// XML escaping. Not part of the public contract: use vtp.h, vtp_polylines.h
// or pvd.h.

#include <tinyxml2.h>

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mmm::mesh::vtk_detail {

// "line 12: ", the prefix of every message about an element.
std::string at_line(const tinyxml2::XMLElement& element);

// Reads and parses the file into `document` and returns its <VTKFile> root,
// checking that its type attribute is `type`. Throws IoError naming the path
// for a missing/empty file, malformed XML (with the line), another root, or
// another type ("the VTKFile type is 'X'; <wrong_type_hint>").
const tinyxml2::XMLElement& load_vtk_file(const std::filesystem::path& path,
                                          tinyxml2::XMLDocument& document, std::string_view type,
                                          std::string_view wrong_type_hint);

// The first child element `name` of `parent`; IoError "<Parent> has no <name>"
// when there is none.
const tinyxml2::XMLElement& required_child(const std::filesystem::path& path,
                                           const tinyxml2::XMLElement& parent, const char* name);

// The <Piece>s of the root's <PolyData>, in file order; IoError when there is
// no <PolyData> or it holds no <Piece>.
std::vector<const tinyxml2::XMLElement*> poly_data_pieces(const std::filesystem::path& path,
                                                          const tinyxml2::XMLElement& root);

// A <Piece> count attribute (NumberOfPoints, NumberOfLines, ...): 0 when it
// is absent and not `required`; IoError when required and absent or when it
// is not a non-negative integer.
std::int64_t count_attribute(const std::filesystem::path& path, const tinyxml2::XMLElement& piece,
                             const char* name, bool required);

// Appends the piece's 3 x num_points coordinates (x0 y0 z0 x1 ...) to
// `coordinates`, whose size / 3 is the number of points read before this
// piece. IoError for a missing or non-ASCII Points array, a component count
// other than 3, a count that disagrees with NumberOfPoints, a non-finite
// coordinate, or more points in total than an int index can address.
// `piece_label` ("Piece 2") prefixes the messages.
void read_points(const std::filesystem::path& path, const tinyxml2::XMLElement& piece,
                 std::int64_t num_points, const std::string& piece_label,
                 std::vector<double>& coordinates);

// Cells of one section (Polys, Strips, Lines) in flat form: cell c holds
// indices[ends[c-1] .. ends[c]) (ends[-1] = 0).
struct Cells {
  std::vector<int> indices;
  std::vector<std::size_t> ends;
};

// Reads the connectivity + offsets DataArrays of the piece's <section_name>
// (absent is fine when num_cells is 0). Every cell must have at least
// `min_points` indices in [0, num_points); they are returned shifted by
// `base` (the points of earlier pieces). Offsets are VTK's one end offset per
// cell; a leading 0 (VTK 9's in-memory layout) is accepted too. IoError for
// missing or non-integer arrays, counts that disagree with `num_cells` or
// with each other, short cells and indices out of range.
Cells read_cells(const std::filesystem::path& path, const tinyxml2::XMLElement& piece,
                 const char* section_name, std::int64_t num_cells, std::int64_t num_points,
                 std::int64_t base, int min_points, const std::string& piece_label);

// Text with & < > " ' replaced by their XML entities (for attribute values).
std::string xml_escape(std::string_view text);

using NamedScalars = std::vector<std::pair<std::string, Eigen::VectorXd>>;

// What a scalar array's values belong to, for the messages of check_arrays.
struct ArrayOwner {
  std::string kind;      // "point" or "cell"
  std::string owner;     // "the mesh has", "the polylines have"
  std::string element;   // singular: "vertex", "triangle", "point", "line"
  std::string elements;  // plural: "vertices", "triangles", "points", "lines"
};

// Throws InvalidInputError ("cannot write <path>: ...") for an array with an
// empty or repeated name, a non-finite value, or a length other than
// `expected` ("... has 8 values but the mesh has 12 triangles (one value per
// triangle)").
void check_arrays(const NamedScalars& arrays, Eigen::Index expected, const ArrayOwner& owner,
                  const std::filesystem::path& path);

// The XML declaration, the <VTKFile type="PolyData" version="1.0"
// byte_order="LittleEndian" header_type="UInt64"> root and <PolyData>.
void append_header(std::string& out);

// <Piece NumberOfPoints=.. NumberOfVerts="0" NumberOfLines=.. NumberOfStrips="0"
// NumberOfPolys=..>
void append_piece_start(std::string& out, Eigen::Index num_points, Eigen::Index num_lines,
                        Eigen::Index num_polys);

// <PointData> / <CellData> (`tag`) with one Float64 DataArray per entry, the
// first marked as the active Scalars; nothing when `arrays` is empty.
void append_scalar_arrays(std::string& out, const char* tag, const NamedScalars& arrays);

// <Points> with one Float64 "x y z" row per point (shortest round-trip text).
void append_points(std::string& out, const Eigen::MatrixX3d& points);

// Integers `per_line` to a text line, each line indented for a DataArray body.
void append_wrapped_integers(std::string& out, const std::vector<std::int64_t>& values,
                             std::size_t per_line);

// Closes the Piece, PolyData and VTKFile elements.
void append_footer(std::string& out);

}  // namespace mmm::mesh::vtk_detail

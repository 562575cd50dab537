#include "core/mesh/io/obj.h"

#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "core/mesh/io/io_common.h"

namespace mmm::mesh {

namespace {

using io_detail::at_line;
using io_detail::describe_token;
using io_detail::TextScanner;

// Parses one face corner (v, v/vt, v/vt/vn or v//vn) into a 0-based index.
int corner_index(const std::filesystem::path& path, std::string_view token, int line,
                 std::size_t num_vertices) {
  const std::string_view index_text = token.substr(0, token.find('/'));
  std::int64_t index = 0;
  if (!io_detail::parse_int(index_text, index)) {
    throw IoError(path, at_line(line) + "face corner " + describe_token(token) +
                            " does not start with a vertex index");
  }
  if (index == 0) {
    throw IoError(path, at_line(line) + "face refers to vertex 0, but OBJ indices start at 1");
  }
  const auto count = static_cast<std::int64_t>(num_vertices);
  const std::int64_t resolved = index > 0 ? index - 1 : count + index;
  if (resolved < 0 || resolved >= count) {
    throw IoError(path, at_line(line) + "face refers to vertex " + std::to_string(index) +
                            " but only " + std::to_string(count) +
                            " vertices are defined (OBJ indices are 1-based; negative ones "
                            "count back from the last vertex defined before the face)");
  }
  return static_cast<int>(resolved);
}

}  // namespace

IndexedMesh read_obj(const std::filesystem::path& path) {
  const std::string data = io_detail::read_whole_file(path);
  TextScanner scanner(data, '#');
  std::vector<double> coordinates;
  std::vector<int> triangles;
  std::vector<int> polygon;
  coordinates.reserve(data.size() / 16);
  triangles.reserve(data.size() / 8);
  do {
    const std::string_view keyword = scanner.token_in_line();
    const int line = scanner.line();
    if (keyword == "v") {
      const std::size_t vertex = coordinates.size() / 3;
      if (vertex >= static_cast<std::size_t>(INT_MAX)) {
        throw IoError(path, at_line(line) + "more vertices than a 32-bit index can address");
      }
      for (int k = 0; k < 3; ++k) {
        const std::string_view token = scanner.token_in_line();
        double value = 0.0;
        if (!io_detail::parse_double(token, value)) {
          throw IoError(path, at_line(line) + "vertex " + std::to_string(vertex + 1) +
                                  " needs 3 coordinates, got " +
                                  (token.empty() ? std::string("only ") + std::to_string(k)
                                                 : describe_token(token)));
        }
        if (!std::isfinite(value)) {
          throw IoError(path, at_line(line) + "vertex " + std::to_string(vertex + 1) +
                                  " has a non-finite coordinate (NaN or inf)");
        }
        coordinates.push_back(value);
      }
    } else if (keyword == "f") {
      polygon.clear();
      for (std::string_view token = scanner.token_in_line(); !token.empty();
           token = scanner.token_in_line()) {
        polygon.push_back(corner_index(path, token, line, coordinates.size() / 3));
      }
      if (polygon.size() < 3) {
        throw IoError(path, at_line(line) + "face has " + std::to_string(polygon.size()) +
                                " corners; a face needs at least 3");
      }
      io_detail::append_fan(polygon, triangles);
    }
    // Everything else (vt, vn, g, o, s, usemtl, mtllib, l, ...) carries no
    // surface geometry and is skipped with the rest of its line.
  } while (scanner.skip_line());
  return io_detail::assemble_mesh(path, coordinates, triangles);
}

void write_obj(const IndexedMesh& mesh, const std::filesystem::path& path) {
  io_detail::check_mesh_for_writing(mesh, path);
  std::string out = "# OBJ written by mmm: " + std::to_string(mesh.V.rows()) + " vertices, " +
                    std::to_string(mesh.F.rows()) + " triangles\n";
  out.reserve(out.size() + static_cast<std::size_t>(mesh.V.rows()) * 64 +
              static_cast<std::size_t>(mesh.F.rows()) * 24);
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    out += 'v';
    for (Eigen::Index k = 0; k < 3; ++k) {
      out += ' ';
      io_detail::append_number(out, mesh.V(v, k));
    }
    out += '\n';
  }
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    out += 'f';
    for (Eigen::Index k = 0; k < 3; ++k) {
      out += ' ';
      io_detail::append_number(out, static_cast<std::int64_t>(mesh.F(f, k)) + 1);
    }
    out += '\n';
  }
  io_detail::write_file_atomically(path, out);
}

}  // namespace mmm::mesh

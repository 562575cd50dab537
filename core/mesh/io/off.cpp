#include "core/mesh/io/off.h"

#include <algorithm>
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

// OFF keywords: [ST][C][N][4][n]OFF. Returns false for tokens that are not a
// keyword at all (the keyword is optional; the counts may come first).
bool is_off_keyword(std::string_view token) {
  return token.size() >= 3 && token.substr(token.size() - 3) == "OFF";
}

void check_off_keyword(const std::filesystem::path& path, std::string_view keyword, int line) {
  std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  if (prefix.starts_with("ST")) prefix.remove_prefix(2);
  if (prefix.starts_with("C")) prefix.remove_prefix(1);
  if (prefix.starts_with("N")) prefix.remove_prefix(1);
  if (prefix.find('4') != std::string_view::npos || prefix.find('n') != std::string_view::npos) {
    throw IoError(path, at_line(line) + describe_token(keyword) +
                            " is a 4D or n-dimensional OFF; only 3D OFF is read");
  }
  if (!prefix.empty()) {
    throw IoError(path, at_line(line) + "unknown OFF keyword " + describe_token(keyword) +
                            " (expected OFF, or COFF/NOFF/STOFF variants)");
  }
}

class OffParser {
 public:
  OffParser(const std::filesystem::path& path, std::string_view data)
      : path_(path), scanner_(data, '#'), data_size_(data.size()) {}

  IndexedMesh parse() {
    std::string_view token = scanner_.token();
    std::int64_t leading_count = 0;
    if (!is_off_keyword(token) && !io_detail::parse_int(token, leading_count)) {
      throw IoError(path_, at_line(scanner_.line()) +
                               "not an OFF file: expected the keyword OFF or the counts line, "
                               "got " +
                               describe_token(token));
    }
    if (is_off_keyword(token)) {
      check_off_keyword(path_, token, scanner_.line());
      token = scanner_.token();
      if (token == "BINARY") {
        throw IoError(path_, at_line(scanner_.line()) +
                                 "binary OFF is not supported; save the mesh as ASCII OFF");
      }
    }
    const std::int64_t num_vertices = count(token, "vertex count");
    const std::int64_t num_faces = count(scanner_.token(), "face count");
    if (num_vertices > INT_MAX) {
      throw IoError(path_, at_line(scanner_.line()) + std::to_string(num_vertices) +
                               " vertices are more than a 32-bit index can address");
    }
    scanner_.skip_line();  // the optional edge count, unused

    // Each value takes at least two bytes, which bounds sane reservations.
    std::vector<double> coordinates;
    coordinates.reserve(3 * static_cast<std::size_t>(std::min<std::int64_t>(
                                num_vertices, static_cast<std::int64_t>(data_size_ / 6))));
    for (std::int64_t v = 0; v < num_vertices; ++v) {
      for (int k = 0; k < 3; ++k) {
        const std::string_view text = k == 0 ? scanner_.token() : scanner_.token_in_line();
        if (text.empty() && k == 0) ends_early(v, num_vertices, "vertices");
        double value = 0.0;
        if (!io_detail::parse_double(text, value)) {
          throw IoError(path_,
                        at_line(scanner_.line()) + "vertex " + std::to_string(v) +
                            " needs 3 coordinates, got " +
                            (text.empty() ? "only " + std::to_string(k) : describe_token(text)));
        }
        if (!std::isfinite(value)) {
          throw IoError(path_, at_line(scanner_.line()) + "vertex " + std::to_string(v) +
                                   " has a non-finite coordinate (NaN or inf)");
        }
        coordinates.push_back(value);
      }
      scanner_.skip_line();  // colours, normals, texture coordinates
    }

    std::vector<int> triangles;
    triangles.reserve(3 * static_cast<std::size_t>(std::min<std::int64_t>(
                              num_faces, static_cast<std::int64_t>(data_size_ / 8))));
    std::vector<int> polygon;
    for (std::int64_t f = 0; f < num_faces; ++f) {
      const std::string_view size_text = scanner_.token();
      if (size_text.empty()) ends_early(f, num_faces, "faces");
      std::int64_t size = 0;
      if (!io_detail::parse_int(size_text, size)) {
        throw IoError(path_, at_line(scanner_.line()) + "face " + std::to_string(f) +
                                 " should start with its number of corners, got " +
                                 describe_token(size_text));
      }
      if (size < 3) {
        throw IoError(path_, at_line(scanner_.line()) + "face " + std::to_string(f) + " has " +
                                 std::to_string(size) + " corners; a face needs at least 3");
      }
      polygon.clear();
      for (std::int64_t k = 0; k < size; ++k) {
        const std::string_view text = scanner_.token_in_line();
        std::int64_t index = 0;
        if (!io_detail::parse_int(text, index)) {
          throw IoError(path_, at_line(scanner_.line()) + "face " + std::to_string(f) +
                                   " announces " + std::to_string(size) + " corners but corner " +
                                   std::to_string(k) + " is " + describe_token(text));
        }
        if (index < 0 || index >= num_vertices) {
          throw IoError(path_, at_line(scanner_.line()) + "face " + std::to_string(f) +
                                   " refers to vertex " + std::to_string(index) + " but only " +
                                   std::to_string(num_vertices) +
                                   " vertices are defined (OFF indices are 0-based)");
        }
        polygon.push_back(static_cast<int>(index));
      }
      io_detail::append_fan(polygon, triangles);
      scanner_.skip_line();  // optional face colour
    }
    return io_detail::assemble_mesh(path_, coordinates, triangles);
  }

 private:
  std::int64_t count(std::string_view text, const std::string& what) const {
    std::int64_t value = 0;
    if (!io_detail::parse_int(text, value) || value < 0) {
      throw IoError(path_, at_line(scanner_.line()) + "expected the " + what +
                               " (a non-negative integer) of the OFF counts line, got " +
                               describe_token(text));
    }
    return value;
  }

  [[noreturn]] void ends_early(std::int64_t read, std::int64_t announced,
                               const std::string& what) const {
    throw IoError(path_, at_line(scanner_.line()) + "the file ends after " + std::to_string(read) +
                             " of the " + std::to_string(announced) + " announced " + what +
                             " (truncated file?)");
  }

  const std::filesystem::path& path_;
  TextScanner scanner_;
  std::size_t data_size_;
};

}  // namespace

IndexedMesh read_off(const std::filesystem::path& path) {
  const std::string data = io_detail::read_whole_file(path);
  return OffParser(path, data).parse();
}

void write_off(const IndexedMesh& mesh, const std::filesystem::path& path) {
  io_detail::check_mesh_for_writing(mesh, path);
  std::string out =
      "OFF\n" + std::to_string(mesh.V.rows()) + " " + std::to_string(mesh.F.rows()) + " 0\n";
  io_detail::append_vertex_and_face_lines(out, mesh);
  io_detail::write_file_atomically(path, out);
}

}  // namespace mmm::mesh

#include "core/mesh/io/io_common.h"

#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <system_error>

#include "core/errors.h"
#include "core/file_bytes.h"

namespace mmm::mesh::io_detail {

namespace fs = std::filesystem;

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

}  // namespace

std::uintmax_t check_mesh_file(const fs::path& path) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (status.type() == fs::file_type::not_found) {
    throw IoError(path, "no such file (check the path and the working directory)");
  }
  if (error) throw IoError(path, "cannot access the file: " + error.message());
  if (fs::is_directory(status)) {
    throw IoError(path, "is a directory, not a mesh file (name the mesh file inside it)");
  }
  if (!fs::is_regular_file(status)) {
    throw IoError(path, "is not a regular file (device, socket or pipe), not a mesh file");
  }
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) throw IoError(path, "cannot determine the file size: " + error.message());
  if (size == 0) throw IoError(path, "file is empty (0 bytes); was it written completely?");
  return size;
}

std::string read_whole_file(const fs::path& path) {
  return read_file_bytes(path, check_mesh_file(path));
}

void write_file_atomically(const fs::path& path, std::string_view bytes) {
  mmm::write_file_atomically(path, bytes, "a mesh file");
}

void check_mesh_for_writing(const IndexedMesh& mesh, const fs::path& path) {
  if (mesh.F.rows() == 0) {
    throw InvalidInputError("cannot write " + path.string() +
                            ": the mesh has no triangles (mesh files must hold at least one)");
  }
  try {
    validate_indices_and_coordinates(mesh);
  } catch (const InvalidInputError& error) {
    throw InvalidInputError("cannot write " + path.string() + ": " + error.what());
  }
}

void append_fan(std::span<const int> polygon, std::vector<int>& triangles) {
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    triangles.push_back(polygon[0]);
    triangles.push_back(polygon[i]);
    triangles.push_back(polygon[i + 1]);
  }
}

IndexedMesh assemble_mesh(const fs::path& path, const std::vector<double>& coordinates,
                          const std::vector<int>& triangles) {
  const std::size_t num_vertices = coordinates.size() / 3;
  const std::size_t num_triangles = triangles.size() / 3;
  if (num_triangles == 0) {
    throw IoError(path, "contains no triangles (" + std::to_string(num_vertices) +
                            " vertices but no faces: a point cloud or an empty surface?)");
  }
  if (num_vertices > static_cast<std::size_t>(INT_MAX)) {
    throw IoError(path, "has " + std::to_string(num_vertices) +
                            " vertices, more than a 32-bit index can address");
  }
  for (std::size_t v = 0; v < num_vertices; ++v) {
    for (std::size_t k = 0; k < 3; ++k) {
      if (!std::isfinite(coordinates[3 * v + k])) {
        throw IoError(path,
                      "vertex " + std::to_string(v) + " has a non-finite coordinate (NaN or inf)");
      }
    }
  }
  const auto limit = static_cast<int>(num_vertices);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (triangles[t] < 0 || triangles[t] >= limit) {
      throw IoError(path, "triangle " + std::to_string(t / 3) + " refers to vertex " +
                              std::to_string(triangles[t]) + " but the file defines " +
                              std::to_string(num_vertices) + " vertices");
    }
  }
  using RowMajorV = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  using RowMajorF = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
  IndexedMesh mesh;
  mesh.V =
      Eigen::Map<const RowMajorV>(coordinates.data(), static_cast<Eigen::Index>(num_vertices), 3);
  mesh.F =
      Eigen::Map<const RowMajorF>(triangles.data(), static_cast<Eigen::Index>(num_triangles), 3);
  return mesh;
}

void append_number(std::string& out, double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), result.ptr);
}

void append_number(std::string& out, float value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), result.ptr);
}

void append_number(std::string& out, std::int64_t value) {
  std::array<char, 24> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), result.ptr);
}

void append_vertex_and_face_lines(std::string& out, const IndexedMesh& mesh) {
  out.reserve(out.size() + static_cast<std::size_t>(mesh.V.rows()) * 64 +
              static_cast<std::size_t>(mesh.F.rows()) * 24);
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    for (Eigen::Index k = 0; k < 3; ++k) {
      if (k > 0) out += ' ';
      append_number(out, mesh.V(v, k));
    }
    out += '\n';
  }
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    out += '3';
    for (Eigen::Index k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, static_cast<std::int64_t>(mesh.F(f, k)));
    }
    out += '\n';
  }
}

bool parse_double(std::string_view token, double& value) {
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') ++first;
  if (first == last) return false;
  const auto result = std::from_chars(first, last, value);
  return result.ec == std::errc() && result.ptr == last;
}

bool parse_int(std::string_view token, std::int64_t& value) {
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') ++first;
  if (first == last) return false;
  const auto result = std::from_chars(first, last, value);
  return result.ec == std::errc() && result.ptr == last;
}

std::string describe_token(std::string_view token) {
  if (token.empty()) return "end of file";
  constexpr std::size_t kMaxShown = 40;
  std::string shown;
  for (const char c : token.substr(0, kMaxShown)) {
    const bool printable = std::isprint(static_cast<unsigned char>(c)) != 0;
    shown.push_back(printable ? c : '?');
  }
  if (token.size() > kMaxShown) shown += "...";
  return "'" + shown + "'";
}

std::string at_line(int line) { return "line " + std::to_string(line) + ": "; }

std::string to_lower(std::string_view text) {
  std::string lower(text);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower;
}

std::string_view TextScanner::token_in_line() {
  while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
  if (pos_ >= text_.size() || text_[pos_] == '\n') return {};
  if (comment_ != '\0' && text_[pos_] == comment_) {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    return {};
  }
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_blank(text_[pos_]) && text_[pos_] != '\n') ++pos_;
  return text_.substr(start, pos_ - start);
}

std::string_view TextScanner::token() {
  while (true) {
    const std::string_view found = token_in_line();
    if (!found.empty()) return found;
    if (!skip_line()) return {};
  }
}

bool TextScanner::skip_line() {
  const std::size_t newline = text_.find('\n', pos_);
  if (newline == std::string_view::npos) {
    pos_ = text_.size();
    return false;
  }
  pos_ = newline + 1;
  ++line_;
  return true;
}

}  // namespace mmm::mesh::io_detail

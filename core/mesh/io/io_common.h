#pragma once
// Pieces shared by the mesh readers and writers of core/mesh/io/: the checks
// made before a file is read, whole-file reading, atomic writing, a small
// line-aware text scanner, number parsing/printing, byte-order helpers and the
// final assembly + validation of a reader's flat arrays into an IndexedMesh.
// Not part of the public contract: use mesh_io.h or the per-format headers.

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::mesh::io_detail {

// Throws IoError unless `path` names an existing, readable-looking, non-empty
// regular file ("no such file", "is a directory, not a mesh file", "file is
// empty", ...). Returns the file size in bytes.
std::uintmax_t check_mesh_file(const std::filesystem::path& path);

// check_mesh_file, then the whole file in one read.
std::string read_whole_file(const std::filesystem::path& path);

// Writes `bytes` to a temporary sibling of `path` and renames it onto `path`,
// so that a crash never leaves a half-written file under the final name. The
// parent folder must exist (nothing but the file is created). IoError on
// failure; the temporary file is removed.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

// Throws InvalidInputError ("cannot write <path>: ...") when the mesh has no
// faces, a non-finite coordinate or a face index outside [0, #V).
void check_mesh_for_writing(const IndexedMesh& mesh, const std::filesystem::path& path);

// Appends the fan triangulation (p0, pi, pi+1) of a polygon with at least 3
// corners to the flat triangle list.
void append_fan(std::span<const int> polygon, std::vector<int>& triangles);

// Builds the mesh from flat arrays (x0 y0 z0 x1 ..., a0 b0 c0 a1 ...).
// Throws IoError naming `path` when there are no triangles ("contains no
// triangles"), more vertices than an int index can address, a non-finite
// coordinate or an index out of range (readers check these earlier with
// better context; this is the last line of defence).
IndexedMesh assemble_mesh(const std::filesystem::path& path, const std::vector<double>& coordinates,
                          const std::vector<int>& triangles);

// Shortest decimal text that reads back to exactly the same value.
void append_number(std::string& out, double value);
void append_number(std::string& out, float value);
void append_number(std::string& out, std::int64_t value);

// The text body shared by OFF and ASCII PLY: one "x y z" line per vertex,
// then one "3 a b c" line per face.
void append_vertex_and_face_lines(std::string& out, const IndexedMesh& mesh);

// Whole-token parsing (a leading '+' is accepted). False when the token is not
// entirely a number or is out of the type's range. "nan"/"inf" parse as doubles
// (callers check finiteness to give a precise message).
bool parse_double(std::string_view token, double& value);
bool parse_int(std::string_view token, std::int64_t& value);

// A token for an error message: quoted and shortened, or "end of file".
std::string describe_token(std::string_view token);

// "line 12: ", the prefix of a message about a text-format line (1-based).
std::string at_line(int line);

// Lower-case copy (ASCII).
std::string to_lower(std::string_view text);

// Whitespace-separated tokens of a text, aware of lines (1-based numbers) and,
// optionally, of comments running from `comment` to the end of the line.
class TextScanner {
 public:
  explicit TextScanner(std::string_view text, char comment = '\0', int first_line = 1)
      : text_(text), comment_(comment), line_(first_line) {}

  // Next token on the current line; empty when the line or a comment ends.
  std::string_view token_in_line();
  // Next token anywhere (crosses line ends, skips comments); empty at the end.
  std::string_view token();
  // Moves to the start of the next line; false when there is none.
  bool skip_line();
  // Line of the current position (of the token just returned).
  [[nodiscard]] int line() const { return line_; }
  // Offset of the current position in the text.
  [[nodiscard]] std::size_t position() const { return pos_; }

 private:
  std::string_view text_;
  char comment_;
  std::size_t pos_ = 0;
  int line_;
};

// Byte-order helpers for binary formats.
template <typename T>
T load_scalar(const char* bytes, bool swap_bytes) {
  std::array<char, sizeof(T)> raw{};
  std::memcpy(raw.data(), bytes, sizeof(T));
  if (swap_bytes) std::reverse(raw.begin(), raw.end());
  T value;
  std::memcpy(&value, raw.data(), sizeof(T));
  return value;
}

template <typename T>
void append_scalar(std::string& out, T value, bool swap_bytes) {
  std::array<char, sizeof(T)> raw{};
  std::memcpy(raw.data(), &value, sizeof(T));
  if (swap_bytes) std::reverse(raw.begin(), raw.end());
  out.append(raw.data(), raw.size());
}

// True when data in `file_order` must be byte-swapped on this machine.
constexpr bool needs_swap(std::endian file_order) { return file_order != std::endian::native; }

}  // namespace mmm::mesh::io_detail

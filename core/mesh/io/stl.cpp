#include "core/mesh/io/stl.h"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "core/errors.h"
#include "core/mesh/io/io_common.h"

namespace mmm::mesh {

namespace {

using io_detail::describe_token;
using io_detail::TextScanner;

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kPreambleBytes = 84;  // header + uint32 triangle count
constexpr std::size_t kRecordBytes = 50;    // normal, 3 corners (float32), uint16 attribute

// Merges corners with exactly equal coordinates (-0 and +0 are equal) into one
// vertex; vertices are numbered in first-occurrence order.
template <typename Scalar>
class VertexWelder {
 public:
  explicit VertexWelder(std::size_t expected_corners) {
    // A closed triangle mesh has about one vertex per six corners.
    map_.reserve(expected_corners / 5 + 16);
    coordinates_.reserve(3 * (expected_corners / 5 + 16));
  }

  int add(Scalar x, Scalar y, Scalar z) {
    // Adding +0 turns -0 into +0 so that equal values hash equally.
    const Key key{x + Scalar(0), y + Scalar(0), z + Scalar(0)};
    const auto [it, inserted] = map_.try_emplace(key, static_cast<int>(map_.size()));
    if (inserted) {
      coordinates_.push_back(static_cast<double>(x));
      coordinates_.push_back(static_cast<double>(y));
      coordinates_.push_back(static_cast<double>(z));
    }
    return it->second;
  }

  [[nodiscard]] const std::vector<double>& coordinates() const { return coordinates_; }

 private:
  using Key = std::array<Scalar, 3>;
  using Bits = std::conditional_t<sizeof(Scalar) == 4, std::uint32_t, std::uint64_t>;

  struct KeyHash {
    std::size_t operator()(const Key& key) const {
      std::uint64_t hash = 0x243F6A8885A308D3ULL;
      for (const Scalar value : key) {
        Bits bits{};
        std::memcpy(&bits, &value, sizeof(bits));
        hash ^=
            static_cast<std::uint64_t>(bits) + 0x9E3779B97F4A7C15ULL + (hash << 6U) + (hash >> 2U);
      }
      // Final avalanche (splitmix64) so that nearby coordinates spread out.
      hash ^= hash >> 30U;
      hash *= 0xBF58476D1CE4E5B9ULL;
      hash ^= hash >> 27U;
      hash *= 0x94D049BB133111EBULL;
      hash ^= hash >> 31U;
      return static_cast<std::size_t>(hash);
    }
  };

  std::unordered_map<Key, int, KeyHash> map_;
  std::vector<double> coordinates_;
};

IndexedMesh read_binary(const std::filesystem::path& path, std::string_view data,
                        std::uint32_t count) {
  const bool swap = io_detail::needs_swap(std::endian::little);
  VertexWelder<float> welder(3 * static_cast<std::size_t>(count));
  std::vector<int> triangles(3 * static_cast<std::size_t>(count));
  for (std::size_t t = 0; t < count; ++t) {
    const char* record = data.data() + kPreambleBytes + kRecordBytes * t;
    for (std::size_t j = 0; j < 3; ++j) {
      const char* corner = record + 12 * (j + 1);
      const auto x = io_detail::load_scalar<float>(corner, swap);
      const auto y = io_detail::load_scalar<float>(corner + 4, swap);
      const auto z = io_detail::load_scalar<float>(corner + 8, swap);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        throw IoError(path, "triangle " + std::to_string(t) + " vertex " + std::to_string(j) +
                                " has a non-finite coordinate (NaN or inf)");
      }
      triangles[3 * t + j] = welder.add(x, y, z);
    }
  }
  return io_detail::assemble_mesh(path, welder.coordinates(), triangles);
}

bool equals_ignoring_case(std::string_view token, std::string_view keyword) {
  if (token.size() != keyword.size()) return false;
  for (std::size_t i = 0; i < token.size(); ++i) {
    const char c = token[i];
    const char lower = (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
    if (lower != keyword[i]) return false;
  }
  return true;
}

class AsciiStlParser {
 public:
  AsciiStlParser(const std::filesystem::path& path, std::string_view data)
      : path_(path), scanner_(data), welder_(data.size() / 40) {}

  IndexedMesh parse() {
    expect("solid");
    scanner_.skip_line();  // the solid's name
    std::vector<int> corners;
    std::size_t facet = 0;
    while (true) {
      const std::string_view token = scanner_.token();
      if (token.empty()) break;  // a missing final "endsolid" is tolerated
      if (equals_ignoring_case(token, "endsolid")) {
        scanner_.skip_line();
        const std::string_view next = scanner_.token();
        if (next.empty()) break;
        if (!equals_ignoring_case(next, "solid")) fail("'solid' or end of file", next);
        scanner_.skip_line();
        continue;
      }
      if (!equals_ignoring_case(token, "facet")) fail("'facet' or 'endsolid'", token);
      expect("normal");
      for (int k = 0; k < 3; ++k) {
        // The stored normal is ignored (it is implied by the corner order);
        // some exporters write "nan" for degenerate facets, so it is not parsed.
        const std::string_view component = scanner_.token();
        if (component.empty()) fail("a normal component", component);
      }
      expect("outer");
      expect("loop");
      corners.clear();
      while (true) {
        const std::string_view keyword = scanner_.token();
        if (equals_ignoring_case(keyword, "endloop")) break;
        if (!equals_ignoring_case(keyword, "vertex")) fail("'vertex' or 'endloop'", keyword);
        std::array<double, 3> xyz{};
        for (double& value : xyz) {
          const std::string_view number = scanner_.token();
          if (!io_detail::parse_double(number, value)) fail("a coordinate", number);
          if (!std::isfinite(value)) {
            throw IoError(path_, "line " + std::to_string(scanner_.line()) + ": triangle " +
                                     std::to_string(facet) + " vertex " +
                                     std::to_string(corners.size()) +
                                     " has a non-finite coordinate (NaN or inf)");
          }
        }
        corners.push_back(welder_.add(xyz[0], xyz[1], xyz[2]));
      }
      if (corners.size() < 3) {
        throw IoError(path_, "line " + std::to_string(scanner_.line()) + ": facet " +
                                 std::to_string(facet) + " has " + std::to_string(corners.size()) +
                                 " vertices; a facet needs at least 3");
      }
      expect("endfacet");
      io_detail::append_fan(corners, triangles_);
      ++facet;
    }
    return io_detail::assemble_mesh(path_, welder_.coordinates(), triangles_);
  }

 private:
  void expect(std::string_view keyword) {
    const std::string_view token = scanner_.token();
    if (!equals_ignoring_case(token, keyword)) fail("'" + std::string(keyword) + "'", token);
  }

  [[noreturn]] void fail(const std::string& expected, std::string_view got) const {
    throw IoError(path_, "line " + std::to_string(scanner_.line()) + ": ASCII STL expects " +
                             expected + ", got " + describe_token(got));
  }

  const std::filesystem::path& path_;
  TextScanner scanner_;
  VertexWelder<double> welder_;
  std::vector<int> triangles_;
};

bool starts_with_solid(std::string_view data) {
  std::size_t pos = 0;
  while (pos < data.size() &&
         (data[pos] == ' ' || data[pos] == '\t' || data[pos] == '\r' || data[pos] == '\n')) {
    ++pos;
  }
  return equals_ignoring_case(data.substr(pos, 5), "solid");
}

std::string size_report(std::uint32_t count, std::uint64_t expected, std::size_t actual) {
  return "header announces " + std::to_string(count) + " triangles (expects " +
         std::to_string(expected) + " bytes) but the file has " + std::to_string(actual) + " bytes";
}

void check_float_range(const IndexedMesh& mesh, const std::filesystem::path& path) {
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    for (Eigen::Index k = 0; k < 3; ++k) {
      if (!std::isfinite(static_cast<float>(mesh.V(v, k)))) {
        throw InvalidInputError("cannot write " + path.string() + ": vertex " + std::to_string(v) +
                                " has a coordinate (" + std::to_string(mesh.V(v, k)) +
                                ") outside the float32 range STL stores");
      }
    }
  }
}

std::array<float, 3> facet_normal(const IndexedMesh& mesh, Eigen::Index f) {
  const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
  const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1));
  const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2));
  Eigen::Vector3d normal = (b - a).cross(c - a);
  const double length = normal.norm();
  if (length > 0.0 && std::isfinite(length)) {
    normal /= length;
  } else {
    normal.setZero();  // degenerate facet: STL readers accept a zero normal
  }
  return {static_cast<float>(normal.x()), static_cast<float>(normal.y()),
          static_cast<float>(normal.z())};
}

std::string binary_bytes(const IndexedMesh& mesh) {
  const bool swap = io_detail::needs_swap(std::endian::little);
  std::string out;
  out.reserve(kPreambleBytes + kRecordBytes * static_cast<std::size_t>(mesh.F.rows()));
  // The header must not start with "solid": some readers would take the file for ASCII.
  std::string header = "binary STL written by mmm";
  header.resize(kHeaderBytes, ' ');
  out += header;
  io_detail::append_scalar(out, static_cast<std::uint32_t>(mesh.F.rows()), swap);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (const float component : facet_normal(mesh, f)) {
      io_detail::append_scalar(out, component, swap);
    }
    for (Eigen::Index j = 0; j < 3; ++j) {
      for (Eigen::Index k = 0; k < 3; ++k) {
        io_detail::append_scalar(out, static_cast<float>(mesh.V(mesh.F(f, j), k)), swap);
      }
    }
    io_detail::append_scalar(out, std::uint16_t{0}, swap);
  }
  return out;
}

std::string ascii_text(const IndexedMesh& mesh) {
  std::string out = "solid mmm\n";
  out.reserve(static_cast<std::size_t>(mesh.F.rows()) * 250);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    out += "  facet normal";
    for (const float component : facet_normal(mesh, f)) {
      out += ' ';
      io_detail::append_number(out, component);
    }
    out += "\n    outer loop\n";
    for (Eigen::Index j = 0; j < 3; ++j) {
      out += "      vertex";
      for (Eigen::Index k = 0; k < 3; ++k) {
        out += ' ';
        io_detail::append_number(out, static_cast<float>(mesh.V(mesh.F(f, j), k)));
      }
      out += '\n';
    }
    out += "    endloop\n  endfacet\n";
  }
  out += "endsolid mmm\n";
  return out;
}

}  // namespace

IndexedMesh read_stl(const std::filesystem::path& path) {
  const std::string data = io_detail::read_whole_file(path);
  std::uint32_t count = 0;
  std::uint64_t expected = 0;
  if (data.size() >= kPreambleBytes) {
    count = io_detail::load_scalar<std::uint32_t>(data.data() + kHeaderBytes,
                                                  io_detail::needs_swap(std::endian::little));
    expected = kPreambleBytes + kRecordBytes * static_cast<std::uint64_t>(count);
    if (data.size() == expected) return read_binary(path, data, count);
  }
  // Text never contains NUL bytes; binary STL nearly always does (attribute
  // bytes, small integers in the count), so a NUL rules out ASCII.
  const bool has_nul = data.find('\0') != std::string::npos;
  if (starts_with_solid(data) && !has_nul) return AsciiStlParser(path, data).parse();
  if (data.size() < kPreambleBytes) {
    throw IoError(path, "truncated binary STL: the file has " + std::to_string(data.size()) +
                            " bytes, fewer than the 84-byte header and triangle count (and it "
                            "does not start with 'solid', so it is not ASCII STL)");
  }
  if (data.size() < expected) {
    throw IoError(path, "truncated binary STL: " + size_report(count, expected, data.size()) +
                            " (the file was cut short; export it again)");
  }
  throw IoError(path, "binary STL size mismatch: " + size_report(count, expected, data.size()) +
                          " (trailing data or a wrong count in the header; export it again)");
}

void write_stl(const IndexedMesh& mesh, const std::filesystem::path& path,
               const StlWriteOptions& options) {
  io_detail::check_mesh_for_writing(mesh, path);
  check_float_range(mesh, path);
  if (static_cast<std::uint64_t>(mesh.F.rows()) > UINT32_MAX) {
    throw InvalidInputError("cannot write " + path.string() + ": " + std::to_string(mesh.F.rows()) +
                            " triangles exceed the 32-bit count of binary STL");
  }
  const std::string bytes = options.ascii ? ascii_text(mesh) : binary_bytes(mesh);
  io_detail::write_file_atomically(path, bytes);
}

}  // namespace mmm::mesh

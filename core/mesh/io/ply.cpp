#include "core/mesh/io/ply.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <optional>
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

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };

struct PlyTypeName {
  std::string_view name;
  PlyType type;
};

constexpr std::array<PlyTypeName, 16> kTypeNames{{
    {"char", PlyType::kInt8},
    {"int8", PlyType::kInt8},
    {"uchar", PlyType::kUInt8},
    {"uint8", PlyType::kUInt8},
    {"short", PlyType::kInt16},
    {"int16", PlyType::kInt16},
    {"ushort", PlyType::kUInt16},
    {"uint16", PlyType::kUInt16},
    {"int", PlyType::kInt32},
    {"int32", PlyType::kInt32},
    {"uint", PlyType::kUInt32},
    {"uint32", PlyType::kUInt32},
    {"float", PlyType::kFloat32},
    {"float32", PlyType::kFloat32},
    {"double", PlyType::kFloat64},
    {"float64", PlyType::kFloat64},
}};

std::size_t type_size(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUInt8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUInt16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUInt32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

bool is_integer(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // the item type for a list
  bool is_list = false;
  PlyType count_type = PlyType::kUInt8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  // first byte after the end_header line
  int data_line = 1;            // line number of that byte (ASCII)
};

PlyType parse_type(const std::filesystem::path& path, std::string_view name, int line) {
  for (const auto& entry : kTypeNames) {
    if (entry.name == name) return entry.type;
  }
  throw IoError(path, at_line(line) + "unknown PLY property type " + describe_token(name) +
                          " (supported: char uchar short ushort int uint float double, or "
                          "int8 uint8 int16 uint16 int32 uint32 float32 float64)");
}

PlyHeader parse_header(const std::filesystem::path& path, std::string_view data) {
  PlyHeader header;
  bool has_format = false;
  std::size_t pos = 0;
  int line = 0;
  while (true) {
    if (pos >= data.size()) {
      throw IoError(path, "the PLY header has no 'end_header' line (truncated file, or not PLY)");
    }
    const std::size_t newline = data.find('\n', pos);
    const std::size_t end = newline == std::string_view::npos ? data.size() : newline;
    ++line;
    TextScanner words(data.substr(pos, end - pos), '\0', line);
    pos = newline == std::string_view::npos ? data.size() : newline + 1;
    const std::string_view keyword = words.token_in_line();
    if (line == 1) {
      if (keyword != "ply") {
        throw IoError(
            path, "not a PLY file: the first line must be 'ply', got " + describe_token(keyword));
      }
      continue;
    }
    if (keyword == "end_header") break;
    if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      const std::string_view encoding = words.token_in_line();
      const std::string_view version = words.token_in_line();
      if (encoding == "ascii") {
        header.encoding = PlyEncoding::kAscii;
      } else if (encoding == "binary_little_endian") {
        header.encoding = PlyEncoding::kBinaryLittleEndian;
      } else if (encoding == "binary_big_endian") {
        header.encoding = PlyEncoding::kBinaryBigEndian;
      } else {
        throw IoError(path, at_line(line) + "unknown PLY format " + describe_token(encoding) +
                                " (expected ascii, binary_little_endian or binary_big_endian)");
      }
      if (!version.starts_with("1")) {
        throw IoError(path, at_line(line) + "unsupported PLY version " + describe_token(version) +
                                " (only 1.0 is read)");
      }
      has_format = true;
    } else if (keyword == "element") {
      PlyElement element;
      element.name = std::string(words.token_in_line());
      const std::string_view count_text = words.token_in_line();
      std::int64_t count = 0;
      if (element.name.empty() || !io_detail::parse_int(count_text, count) || count < 0) {
        throw IoError(path, at_line(line) +
                                "an element line needs a name and a non-negative count, got " +
                                describe_token(count_text));
      }
      element.count = static_cast<std::uint64_t>(count);
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) {
        throw IoError(path, at_line(line) + "property declared before any element");
      }
      PlyProperty property;
      std::string_view type_name = words.token_in_line();
      if (type_name == "list") {
        property.is_list = true;
        const std::string_view count_type = words.token_in_line();
        property.count_type = parse_type(path, count_type, line);
        if (!is_integer(property.count_type)) {
          throw IoError(path, at_line(line) + "a list count type must be an integer type, got " +
                                  describe_token(count_type));
        }
        type_name = words.token_in_line();
      }
      property.type = parse_type(path, type_name, line);
      property.name = std::string(words.token_in_line());
      if (property.name.empty()) throw IoError(path, at_line(line) + "property without a name");
      header.elements.back().properties.push_back(std::move(property));
    } else {
      throw IoError(path, at_line(line) + "unknown PLY header keyword " + describe_token(keyword));
    }
  }
  if (!has_format) throw IoError(path, "the PLY header has no 'format' line");
  header.data_offset = pos;
  header.data_line = line + 1;
  return header;
}

// Where a value sits, for error messages (built only when one is thrown).
struct Where {
  const PlyElement& element;
  std::uint64_t index;
  const PlyProperty& property;

  [[nodiscard]] std::string describe() const {
    return "property '" + property.name + "' of " + element.name + " " + std::to_string(index) +
           " (element '" + element.name + "' announces " + std::to_string(element.count) + ")";
  }
};

class AsciiSource {
 public:
  AsciiSource(const std::filesystem::path& path, std::string_view body, int first_line)
      : path_(path), scanner_(body, '\0', first_line) {}

  double read(PlyType /*type*/, const Where& where) {
    const std::string_view token = scanner_.token();
    if (token.empty()) {
      throw IoError(path_, at_line(scanner_.line()) + "the file ends inside " + where.describe() +
                               " (truncated file?)");
    }
    double value = 0.0;
    if (!io_detail::parse_double(token, value)) {
      throw IoError(path_, at_line(scanner_.line()) + "expected a number for " + where.describe() +
                               ", got " + describe_token(token));
    }
    return value;
  }

  void skip(PlyType type, const Where& where) { read(type, where); }

  [[nodiscard]] std::string location() const { return at_line(scanner_.line()); }

 private:
  const std::filesystem::path& path_;
  TextScanner scanner_;
};

class BinarySource {
 public:
  BinarySource(const std::filesystem::path& path, std::string_view body, std::size_t file_size,
               std::endian order)
      : path_(path), body_(body), file_size_(file_size), swap_(io_detail::needs_swap(order)) {}

  double read(PlyType type, const Where& where) {
    const char* bytes = take(type_size(type), where);
    switch (type) {
      case PlyType::kInt8:
        return io_detail::load_scalar<std::int8_t>(bytes, swap_);
      case PlyType::kUInt8:
        return io_detail::load_scalar<std::uint8_t>(bytes, swap_);
      case PlyType::kInt16:
        return io_detail::load_scalar<std::int16_t>(bytes, swap_);
      case PlyType::kUInt16:
        return io_detail::load_scalar<std::uint16_t>(bytes, swap_);
      case PlyType::kInt32:
        return io_detail::load_scalar<std::int32_t>(bytes, swap_);
      case PlyType::kUInt32:
        return io_detail::load_scalar<std::uint32_t>(bytes, swap_);
      case PlyType::kFloat32:
        return io_detail::load_scalar<float>(bytes, swap_);
      case PlyType::kFloat64:
        return io_detail::load_scalar<double>(bytes, swap_);
    }
    return 0.0;
  }

  void skip(PlyType type, const Where& where) { take(type_size(type), where); }

  [[nodiscard]] static std::string location() { return {}; }

 private:
  const char* take(std::size_t size, const Where& where) {
    if (body_.size() - pos_ < size) {
      throw IoError(path_, "truncated binary PLY: the file (" + std::to_string(file_size_) +
                               " bytes) ends inside " + where.describe());
    }
    const char* bytes = body_.data() + pos_;
    pos_ += size;
    return bytes;
  }

  const std::filesystem::path& path_;
  std::string_view body_;
  std::size_t file_size_;
  bool swap_;
  std::size_t pos_ = 0;
};

// Vertex coordinates and polygons gathered from the body.
struct PlyContent {
  std::vector<double> coordinates;
  std::vector<std::int64_t> corners;    // polygon corners, concatenated
  std::vector<std::size_t> face_sizes;  // corners per polygon
  bool has_vertices = false;
};

// Reading a list count: an integer >= 0 (ASCII data could hold anything).
template <typename Source>
std::uint64_t read_list_count(const std::filesystem::path& path, Source& source,
                              const PlyProperty& property, const Where& where) {
  const double count = source.read(property.count_type, where);
  if (!(count >= 0.0) || count != std::floor(count) || count > 1e9) {
    throw IoError(path, source.location() + "list count " + std::to_string(count) + " of " +
                            where.describe() + " is not a valid count");
  }
  return static_cast<std::uint64_t>(count);
}

template <typename Source>
void read_vertices(const std::filesystem::path& path, Source& source, const PlyElement& element,
                   std::size_t reserve, PlyContent& content) {
  if (content.has_vertices) throw IoError(path, "the PLY file has two 'vertex' elements");
  content.has_vertices = true;
  if (element.count > static_cast<std::uint64_t>(INT_MAX)) {
    throw IoError(path, "element 'vertex' announces " + std::to_string(element.count) +
                            " vertices, more than a 32-bit index can address");
  }
  std::vector<int> slot(element.properties.size(), -1);
  for (int axis = 0; axis < 3; ++axis) {
    const std::string name(1, static_cast<char>('x' + axis));
    const auto found =
        std::find_if(element.properties.begin(), element.properties.end(),
                     [&name](const PlyProperty& property) { return property.name == name; });
    if (found == element.properties.end() || found->is_list) {
      throw IoError(path, "element 'vertex' has no scalar property '" + name +
                              "' (vertex positions need x, y and z)");
    }
    slot[static_cast<std::size_t>(found - element.properties.begin())] = axis;
  }
  content.coordinates.reserve(3 * reserve);
  std::array<double, 3> xyz{};
  for (std::uint64_t i = 0; i < element.count; ++i) {
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      const Where where{element, i, property};
      if (property.is_list) {
        const std::uint64_t count = read_list_count(path, source, property, where);
        for (std::uint64_t k = 0; k < count; ++k) source.skip(property.type, where);
      } else if (slot[p] >= 0) {
        xyz[static_cast<std::size_t>(slot[p])] = source.read(property.type, where);
      } else {
        source.skip(property.type, where);
      }
    }
    if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) {
      throw IoError(path, source.location() + "vertex " + std::to_string(i) +
                              " has a non-finite coordinate (NaN or inf)");
    }
    content.coordinates.insert(content.coordinates.end(), xyz.begin(), xyz.end());
  }
}

template <typename Source>
void read_faces(const std::filesystem::path& path, Source& source, const PlyElement& element,
                std::size_t reserve, PlyContent& content) {
  const auto found =
      std::find_if(element.properties.begin(), element.properties.end(), [](const auto& property) {
        return property.name == "vertex_indices" || property.name == "vertex_index";
      });
  if (found == element.properties.end() || !found->is_list) {
    throw IoError(path, "element 'face' has no list property 'vertex_indices' (or 'vertex_index')");
  }
  const auto index_property = static_cast<std::size_t>(found - element.properties.begin());
  content.face_sizes.reserve(reserve);
  content.corners.reserve(3 * reserve);
  for (std::uint64_t i = 0; i < element.count; ++i) {
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      const Where where{element, i, property};
      if (!property.is_list) {
        source.skip(property.type, where);
        continue;
      }
      const std::uint64_t count = read_list_count(path, source, property, where);
      if (p != index_property) {
        for (std::uint64_t k = 0; k < count; ++k) source.skip(property.type, where);
        continue;
      }
      if (count < 3) {
        throw IoError(path, source.location() + "face " + std::to_string(i) + " has " +
                                std::to_string(count) + " corners; a face needs at least 3");
      }
      for (std::uint64_t k = 0; k < count; ++k) {
        const double index = source.read(property.type, where);
        if (index != std::floor(index) || std::abs(index) > 1e18) {
          throw IoError(path, source.location() + "face " + std::to_string(i) + " corner " +
                                  std::to_string(k) + " is " + std::to_string(index) +
                                  ", not a vertex index");
        }
        content.corners.push_back(static_cast<std::int64_t>(index));
      }
      content.face_sizes.push_back(static_cast<std::size_t>(count));
    }
  }
}

template <typename Source>
void skip_element(const std::filesystem::path& path, Source& source, const PlyElement& element) {
  for (std::uint64_t i = 0; i < element.count; ++i) {
    for (const PlyProperty& property : element.properties) {
      const Where where{element, i, property};
      const std::uint64_t count =
          property.is_list ? read_list_count(path, source, property, where) : 1;
      for (std::uint64_t k = 0; k < count; ++k) source.skip(property.type, where);
    }
  }
}

// Smallest number of bytes one element occupies in the body: a bound that
// keeps reservations sane when a header announces absurd counts.
std::size_t min_element_bytes(const PlyElement& element, bool ascii) {
  std::size_t bytes = 0;
  for (const PlyProperty& property : element.properties) {
    if (ascii) {
      bytes += 2;  // one digit and one separator
    } else {
      bytes += type_size(property.is_list ? property.count_type : property.type);
    }
  }
  return std::max<std::size_t>(bytes, 1);
}

template <typename Source>
PlyContent read_body(const std::filesystem::path& path, Source& source, const PlyHeader& header,
                     std::size_t body_size) {
  PlyContent content;
  const bool ascii = header.encoding == PlyEncoding::kAscii;
  for (const PlyElement& element : header.elements) {
    const std::size_t reserve = static_cast<std::size_t>(
        std::min<std::uint64_t>(element.count, body_size / min_element_bytes(element, ascii)));
    if (element.name == "vertex") {
      read_vertices(path, source, element, reserve, content);
    } else if (element.name == "face") {
      read_faces(path, source, element, reserve, content);
    } else {
      skip_element(path, source, element);
    }
  }
  return content;
}

IndexedMesh assemble(const std::filesystem::path& path, const PlyContent& content) {
  if (!content.has_vertices) {
    throw IoError(path, "the PLY file has no 'vertex' element (it is not a surface mesh)");
  }
  const auto num_vertices = static_cast<std::int64_t>(content.coordinates.size() / 3);
  std::vector<int> triangles;
  triangles.reserve(3 * content.corners.size());
  std::vector<int> polygon;
  std::size_t next = 0;
  for (std::size_t f = 0; f < content.face_sizes.size(); ++f) {
    polygon.clear();
    for (std::size_t k = 0; k < content.face_sizes[f]; ++k, ++next) {
      const std::int64_t index = content.corners[next];
      if (index < 0 || index >= num_vertices) {
        throw IoError(path, "face " + std::to_string(f) + " refers to vertex " +
                                std::to_string(index) + " but only " +
                                std::to_string(num_vertices) +
                                " vertices are defined (PLY indices are 0-based)");
      }
      polygon.push_back(static_cast<int>(index));
    }
    io_detail::append_fan(polygon, triangles);
  }
  return io_detail::assemble_mesh(path, content.coordinates, triangles);
}

std::string header_text(const IndexedMesh& mesh, bool ascii) {
  return std::string("ply\nformat ") + (ascii ? "ascii" : "binary_little_endian") +
         " 1.0\ncomment written by mmm\nelement vertex " + std::to_string(mesh.V.rows()) +
         "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
         std::to_string(mesh.F.rows()) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

}  // namespace

IndexedMesh read_ply(const std::filesystem::path& path) {
  const std::string data = io_detail::read_whole_file(path);
  const PlyHeader header = parse_header(path, data);
  const std::string_view body = std::string_view(data).substr(header.data_offset);
  PlyContent content;
  if (header.encoding == PlyEncoding::kAscii) {
    AsciiSource source(path, body, header.data_line);
    content = read_body(path, source, header, body.size());
  } else {
    const std::endian order = header.encoding == PlyEncoding::kBinaryLittleEndian
                                  ? std::endian::little
                                  : std::endian::big;
    BinarySource source(path, body, data.size(), order);
    content = read_body(path, source, header, body.size());
  }
  return assemble(path, content);
}

void write_ply(const IndexedMesh& mesh, const std::filesystem::path& path,
               const PlyWriteOptions& options) {
  io_detail::check_mesh_for_writing(mesh, path);
  std::string out = header_text(mesh, options.ascii);
  if (options.ascii) {
    io_detail::append_vertex_and_face_lines(out, mesh);
  } else {
    const bool swap = io_detail::needs_swap(std::endian::little);
    out.reserve(out.size() + static_cast<std::size_t>(mesh.V.rows()) * 24 +
                static_cast<std::size_t>(mesh.F.rows()) * 13);
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
      for (Eigen::Index k = 0; k < 3; ++k) io_detail::append_scalar(out, mesh.V(v, k), swap);
    }
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
      io_detail::append_scalar(out, std::uint8_t{3}, swap);
      for (Eigen::Index k = 0; k < 3; ++k) {
        io_detail::append_scalar(out, static_cast<std::int32_t>(mesh.F(f, k)), swap);
      }
    }
  }
  io_detail::write_file_atomically(path, out);
}

}  // namespace mmm::mesh

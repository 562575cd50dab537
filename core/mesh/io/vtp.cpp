#include "core/mesh/io/vtp.h"

#include <tinyxml2.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "core/mesh/io/io_common.h"

namespace mmm::mesh {

namespace {

using io_detail::describe_token;
using io_detail::TextScanner;

std::string at_line(const tinyxml2::XMLElement& element) {
  return "line " + std::to_string(element.GetLineNum()) + ": ";
}

std::string array_label(const tinyxml2::XMLElement& array, std::string_view section) {
  const char* name = array.Attribute("Name");
  return std::string(section) + " DataArray" +
         (name != nullptr ? " '" + std::string(name) + "'" : "");
}

constexpr std::array<std::string_view, 8> kIntegerTypes = {"Int8",  "UInt8",  "Int16", "UInt16",
                                                           "Int32", "UInt32", "Int64", "UInt64"};

bool is_integer_type(std::string_view type) {
  return std::find(kIntegerTypes.begin(), kIntegerTypes.end(), type) != kIntegerTypes.end();
}

// Only format="ascii" arrays are read; binary and appended data are base64 /
// raw (often zlib-compressed) blocks this reader does not decode.
void check_ascii_array(const std::filesystem::path& path, const tinyxml2::XMLElement& array,
                       std::string_view section, bool integer) {
  const char* format = array.Attribute("format");
  const std::string_view format_name = format != nullptr ? format : "ascii";
  if (format_name == "binary" || format_name == "appended") {
    throw IoError(path, at_line(array) + array_label(array, section) + " uses format=\"" +
                            std::string(format_name) +
                            "\"; only ASCII VTP is read. Re-save the file with the ASCII data "
                            "mode (ParaView: File > Save Data, Data Mode 'Ascii'; VTK: "
                            "writer->SetDataModeToAscii())");
  }
  if (format_name != "ascii") {
    throw IoError(path, at_line(array) + array_label(array, section) + " has unknown format " +
                            describe_token(format_name) + " (expected ascii)");
  }
  const char* type = array.Attribute("type");
  const std::string_view type_name = type != nullptr ? type : "";
  const bool known = is_integer_type(type_name) || type_name == "Float32" || type_name == "Float64";
  if (!known || (integer && !is_integer_type(type_name))) {
    throw IoError(path,
                  at_line(array) + array_label(array, section) + " has type " +
                      describe_token(type_name) + ", expected " +
                      (integer ? "an integer type (Int32, Int64, ...)" : "Float32 or Float64"));
  }
}

std::vector<double> parse_reals(const std::filesystem::path& path,
                                const tinyxml2::XMLElement& array, std::string_view section) {
  const char* text = array.GetText();
  std::vector<double> values;
  if (text == nullptr) return values;
  TextScanner scanner(text, '\0', array.GetLineNum());
  for (std::string_view token = scanner.token(); !token.empty(); token = scanner.token()) {
    double value = 0.0;
    if (!io_detail::parse_double(token, value)) {
      throw IoError(path, "line " + std::to_string(scanner.line()) + ": " +
                              array_label(array, section) + " holds " + describe_token(token) +
                              ", not a number");
    }
    values.push_back(value);
  }
  return values;
}

std::vector<std::int64_t> parse_integers(const std::filesystem::path& path,
                                         const tinyxml2::XMLElement& array,
                                         std::string_view section) {
  const char* text = array.GetText();
  std::vector<std::int64_t> values;
  if (text == nullptr) return values;
  TextScanner scanner(text, '\0', array.GetLineNum());
  for (std::string_view token = scanner.token(); !token.empty(); token = scanner.token()) {
    std::int64_t value = 0;
    if (!io_detail::parse_int(token, value)) {
      throw IoError(path, "line " + std::to_string(scanner.line()) + ": " +
                              array_label(array, section) + " holds " + describe_token(token) +
                              ", not an integer");
    }
    values.push_back(value);
  }
  return values;
}

std::int64_t count_attribute(const std::filesystem::path& path, const tinyxml2::XMLElement& piece,
                             const char* name, bool required) {
  const char* text = piece.Attribute(name);
  if (text == nullptr) {
    if (!required) return 0;
    throw IoError(path, at_line(piece) + "<Piece> has no " + name + " attribute");
  }
  std::int64_t value = 0;
  if (!io_detail::parse_int(text, value) || value < 0) {
    throw IoError(path, at_line(piece) + "<Piece> " + name + "=" + describe_token(text) +
                            " is not a non-negative integer");
  }
  return value;
}

const tinyxml2::XMLElement* named_array(const tinyxml2::XMLElement& section,
                                        std::string_view name) {
  for (const auto* array = section.FirstChildElement("DataArray"); array != nullptr;
       array = array->NextSiblingElement("DataArray")) {
    const char* array_name = array->Attribute("Name");
    if (array_name != nullptr && array_name == name) return array;
  }
  return nullptr;
}

class VtpReader {
 public:
  explicit VtpReader(const std::filesystem::path& path) : path_(path) {}

  IndexedMesh read() {
    const std::string data = io_detail::read_whole_file(path_);
    tinyxml2::XMLDocument document;
    if (document.Parse(data.data(), data.size()) != tinyxml2::XML_SUCCESS) {
      const char* detail = document.ErrorStr();
      throw IoError(path_, "malformed XML at line " + std::to_string(document.ErrorLineNum()) +
                               ": " + (detail != nullptr ? detail : document.ErrorName()) +
                               " (truncated or hand-edited file?)");
    }
    const tinyxml2::XMLElement* root = document.RootElement();
    if (root == nullptr || std::string_view(root->Name()) != "VTKFile") {
      throw IoError(path_, "not a VTK XML file: the root element is not <VTKFile>");
    }
    const char* type = root->Attribute("type");
    if (type == nullptr || std::string_view(type) != "PolyData") {
      throw IoError(path_, "the VTKFile type is " + describe_token(type != nullptr ? type : "") +
                               "; only PolyData (.vtp) is read as a surface");
    }
    const tinyxml2::XMLElement* poly_data = root->FirstChildElement("PolyData");
    if (poly_data == nullptr) throw IoError(path_, at_line(*root) + "<VTKFile> has no <PolyData>");
    int piece_number = 0;
    for (const auto* piece = poly_data->FirstChildElement("Piece"); piece != nullptr;
         piece = piece->NextSiblingElement("Piece"), ++piece_number) {
      read_piece(*piece, piece_number);
    }
    if (piece_number == 0) throw IoError(path_, at_line(*poly_data) + "<PolyData> has no <Piece>");
    return io_detail::assemble_mesh(path_, coordinates_, triangles_);
  }

 private:
  void read_piece(const tinyxml2::XMLElement& piece, int piece_number) {
    piece_label_ = "Piece " + std::to_string(piece_number);
    const std::int64_t num_points = count_attribute(path_, piece, "NumberOfPoints", true);
    const std::int64_t num_polys = count_attribute(path_, piece, "NumberOfPolys", false);
    const std::int64_t num_strips = count_attribute(path_, piece, "NumberOfStrips", false);
    const auto base = static_cast<std::int64_t>(coordinates_.size() / 3);
    if (base + num_points > INT_MAX) {
      throw IoError(path_, at_line(piece) + "more points than a 32-bit index can address");
    }
    if (num_points > 0) read_points(piece, num_points);
    read_cells(piece, "Polys", num_polys, num_points, base, false);
    read_cells(piece, "Strips", num_strips, num_points, base, true);
  }

  void read_points(const tinyxml2::XMLElement& piece, std::int64_t num_points) {
    const tinyxml2::XMLElement* points = piece.FirstChildElement("Points");
    const tinyxml2::XMLElement* array =
        points != nullptr ? points->FirstChildElement("DataArray") : nullptr;
    if (array == nullptr) {
      throw IoError(path_, at_line(piece) + piece_label_ + " announces " +
                               std::to_string(num_points) +
                               " points but has no <Points><DataArray>");
    }
    check_ascii_array(path_, *array, "Points", false);
    const int components = array->IntAttribute("NumberOfComponents", 1);
    if (components != 3) {
      throw IoError(path_, at_line(*array) + "the Points DataArray has NumberOfComponents=" +
                               std::to_string(components) + ", expected 3");
    }
    const std::vector<double> values = parse_reals(path_, *array, "Points");
    if (static_cast<std::int64_t>(values.size()) != 3 * num_points) {
      throw IoError(path_, at_line(*array) + piece_label_ + " Points DataArray holds " +
                               std::to_string(values.size()) + " numbers, expected 3 x " +
                               std::to_string(num_points) + " (NumberOfPoints)");
    }
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) {
        throw IoError(path_, at_line(*array) + piece_label_ + " point " + std::to_string(i / 3) +
                                 " has a non-finite coordinate (NaN or inf)");
      }
    }
    coordinates_.insert(coordinates_.end(), values.begin(), values.end());
  }

  void read_cells(const tinyxml2::XMLElement& piece, const char* section_name,
                  std::int64_t num_cells, std::int64_t num_points, std::int64_t base, bool strips) {
    const tinyxml2::XMLElement* section = piece.FirstChildElement(section_name);
    if (section == nullptr) {
      if (num_cells == 0) return;
      throw IoError(path_, at_line(piece) + piece_label_ + " announces " +
                               std::to_string(num_cells) + " " + section_name + " but has no <" +
                               section_name + "> element");
    }
    const std::string label = piece_label_ + " " + section_name;
    const tinyxml2::XMLElement* connectivity_array = named_array(*section, "connectivity");
    const tinyxml2::XMLElement* offsets_array = named_array(*section, "offsets");
    if (connectivity_array == nullptr || offsets_array == nullptr) {
      throw IoError(path_, at_line(*section) + label +
                               " needs DataArrays named 'connectivity' and 'offsets'");
    }
    check_ascii_array(path_, *connectivity_array, section_name, true);
    check_ascii_array(path_, *offsets_array, section_name, true);
    const std::vector<std::int64_t> connectivity =
        parse_integers(path_, *connectivity_array, section_name);
    std::vector<std::int64_t> offsets = parse_integers(path_, *offsets_array, section_name);
    // VTK writes one end offset per cell; a leading 0 (in-memory layout of
    // VTK 9) is accepted too.
    if (static_cast<std::int64_t>(offsets.size()) == num_cells + 1 && !offsets.empty() &&
        offsets.front() == 0) {
      offsets.erase(offsets.begin());
    }
    if (static_cast<std::int64_t>(offsets.size()) != num_cells) {
      throw IoError(path_, at_line(*offsets_array) + label + " offsets hold " +
                               std::to_string(offsets.size()) + " values but the Piece announces " +
                               std::to_string(num_cells) + " cells");
    }
    const std::int64_t total = offsets.empty() ? 0 : offsets.back();
    if (total != static_cast<std::int64_t>(connectivity.size())) {
      throw IoError(path_, at_line(*offsets_array) + label + " last offset is " +
                               std::to_string(total) + " but connectivity holds " +
                               std::to_string(connectivity.size()) + " indices");
    }
    std::vector<int> cell;
    std::int64_t start = 0;
    for (std::size_t c = 0; c < offsets.size(); ++c) {
      const std::int64_t end = offsets[c];
      if (end - start < 3) {
        throw IoError(path_, at_line(*offsets_array) + label + " cell " + std::to_string(c) +
                                 " has " + std::to_string(std::max<std::int64_t>(end - start, 0)) +
                                 " points (offsets must increase by at least 3)");
      }
      cell.clear();
      for (std::int64_t k = start; k < end; ++k) {
        const std::int64_t index = connectivity[static_cast<std::size_t>(k)];
        if (index < 0 || index >= num_points) {
          throw IoError(path_, at_line(*connectivity_array) + label + " cell " + std::to_string(c) +
                                   " refers to point " + std::to_string(index) +
                                   " but the piece has " + std::to_string(num_points) + " points");
        }
        cell.push_back(static_cast<int>(base + index));
      }
      if (strips) {
        append_strip(cell);
      } else {
        io_detail::append_fan(cell, triangles_);
      }
      start = end;
    }
  }

  // Triangle strip p0 p1 p2 p3 ...: triangles (p0 p1 p2), (p2 p1 p3), (p2 p3 p4), ...
  // swapping the first two corners of every odd triangle keeps the orientation.
  void append_strip(const std::vector<int>& strip) {
    for (std::size_t j = 0; j + 2 < strip.size(); ++j) {
      const bool odd = (j % 2) == 1;
      triangles_.push_back(odd ? strip[j + 1] : strip[j]);
      triangles_.push_back(odd ? strip[j] : strip[j + 1]);
      triangles_.push_back(strip[j + 2]);
    }
  }

  const std::filesystem::path& path_;
  std::string piece_label_;
  std::vector<double> coordinates_;
  std::vector<int> triangles_;
};

std::string xml_escape(std::string_view text) {
  std::string escaped;
  for (const char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&apos;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

void check_array(const std::string& name, const Eigen::VectorXd& values, Eigen::Index expected,
                 const std::string& kind, const std::string& element,
                 const std::filesystem::path& path) {
  const std::string where = "cannot write " + path.string() + ": " + kind + " array '" + name + "'";
  if (name.empty()) {
    throw InvalidInputError("cannot write " + path.string() + ": a " + kind +
                            " array has an empty name (ParaView lists arrays by name)");
  }
  if (values.size() != expected) {
    throw InvalidInputError(where + " has " + std::to_string(values.size()) +
                            " values but the mesh has " + std::to_string(expected) + " " + element +
                            " (one value per " + element.substr(0, element.size() - 1) + ")");
  }
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values(i))) {
      throw InvalidInputError(where + " value " + std::to_string(i) +
                              " is not finite (VTK ASCII readers reject NaN/inf)");
    }
  }
}

[[noreturn]] void throw_duplicate_name(const std::string& name, const std::string& kind,
                                       const std::filesystem::path& path) {
  throw InvalidInputError("cannot write " + path.string() + ": " + kind + " array '" + name +
                          "' appears twice (names must be unique)");
}

void check_arrays(const std::vector<std::pair<std::string, Eigen::VectorXd>>& arrays,
                  Eigen::Index expected, const std::string& kind, const std::string& element,
                  const std::filesystem::path& path) {
  std::set<std::string> names;
  for (const auto& [name, values] : arrays) {
    check_array(name, values, expected, kind, element, path);
    if (!names.insert(name).second) throw_duplicate_name(name, kind, path);
  }
}

void append_scalar_arrays(std::string& out, const char* tag,
                          const std::vector<std::pair<std::string, Eigen::VectorXd>>& arrays) {
  if (arrays.empty()) return;
  out += "      <";
  out += tag;
  out += " Scalars=\"" + xml_escape(arrays.front().first) + "\">\n";
  for (const auto& [name, values] : arrays) {
    out += R"(        <DataArray type="Float64" Name=")";
    out += xml_escape(name);
    out += "\" format=\"ascii\">\n";
    constexpr Eigen::Index kPerLine = 6;
    for (Eigen::Index i = 0; i < values.size(); ++i) {
      out += (i % kPerLine == 0) ? "          " : " ";
      io_detail::append_number(out, values(i));
      if (i % kPerLine == kPerLine - 1 || i + 1 == values.size()) out += '\n';
    }
    out += "        </DataArray>\n";
  }
  out += "      </";
  out += tag;
  out += ">\n";
}

}  // namespace

IndexedMesh read_vtp(const std::filesystem::path& path) { return VtpReader(path).read(); }

void write_vtp(const IndexedMesh& mesh, const std::filesystem::path& path,
               const VtpArrays& arrays) {
  io_detail::check_mesh_for_writing(mesh, path);
  check_arrays(arrays.point_scalars, mesh.V.rows(), "point", "vertices", path);
  check_arrays(arrays.cell_scalars, mesh.F.rows(), "cell", "triangles", path);

  std::string out =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <PolyData>\n";
  out.reserve(static_cast<std::size_t>(mesh.V.rows()) * 64 +
              static_cast<std::size_t>(mesh.F.rows()) * 40 + 1024);
  out += R"(    <Piece NumberOfPoints=")";
  out += std::to_string(mesh.V.rows());
  out += R"(" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys=")";
  out += std::to_string(mesh.F.rows());
  out += "\">\n";
  append_scalar_arrays(out, "PointData", arrays.point_scalars);
  append_scalar_arrays(out, "CellData", arrays.cell_scalars);

  out +=
      "      <Points>\n"
      "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
      "format=\"ascii\">\n";
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    out += "          ";
    for (Eigen::Index k = 0; k < 3; ++k) {
      if (k > 0) out += ' ';
      io_detail::append_number(out, mesh.V(v, k));
    }
    out += '\n';
  }
  out +=
      "        </DataArray>\n"
      "      </Points>\n"
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
  constexpr Eigen::Index kOffsetsPerLine = 10;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    out += (f % kOffsetsPerLine == 0) ? "          " : " ";
    io_detail::append_number(out, static_cast<std::int64_t>(3 * (f + 1)));
    if (f % kOffsetsPerLine == kOffsetsPerLine - 1 || f + 1 == mesh.F.rows()) out += '\n';
  }
  out +=
      "        </DataArray>\n"
      "      </Polys>\n"
      "    </Piece>\n"
      "  </PolyData>\n"
      "</VTKFile>\n";
  io_detail::write_file_atomically(path, out);
}

}  // namespace mmm::mesh

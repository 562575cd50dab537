#include "core/mesh/io/vtp_common.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <set>

#include "core/errors.h"
#include "core/mesh/io/io_common.h"

namespace mmm::mesh::vtk_detail {

namespace {

using io_detail::describe_token;
using io_detail::TextScanner;

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

const tinyxml2::XMLElement* named_array(const tinyxml2::XMLElement& section,
                                        std::string_view name) {
  for (const auto* array = section.FirstChildElement("DataArray"); array != nullptr;
       array = array->NextSiblingElement("DataArray")) {
    const char* array_name = array->Attribute("Name");
    if (array_name != nullptr && array_name == name) return array;
  }
  return nullptr;
}

void check_array(const std::string& name, const Eigen::VectorXd& values, Eigen::Index expected,
                 const ArrayOwner& owner, const std::filesystem::path& path) {
  const std::string where =
      "cannot write " + path.string() + ": " + owner.kind + " array '" + name + "'";
  if (name.empty()) {
    throw InvalidInputError("cannot write " + path.string() + ": a " + owner.kind +
                            " array has an empty name (ParaView lists arrays by name)");
  }
  if (values.size() != expected) {
    throw InvalidInputError(where + " has " + std::to_string(values.size()) + " values but " +
                            owner.owner + " " + std::to_string(expected) + " " + owner.elements +
                            " (one value per " + owner.element + ")");
  }
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values(i))) {
      throw InvalidInputError(where + " value " + std::to_string(i) +
                              " is not finite (VTK ASCII readers reject NaN/inf)");
    }
  }
}

}  // namespace

std::string at_line(const tinyxml2::XMLElement& element) {
  return "line " + std::to_string(element.GetLineNum()) + ": ";
}

const tinyxml2::XMLElement& load_vtk_file(const std::filesystem::path& path,
                                          tinyxml2::XMLDocument& document, std::string_view type,
                                          std::string_view wrong_type_hint) {
  const std::string data = io_detail::read_whole_file(path);
  if (document.Parse(data.data(), data.size()) != tinyxml2::XML_SUCCESS) {
    const char* detail = document.ErrorStr();
    throw IoError(path, "malformed XML at line " + std::to_string(document.ErrorLineNum()) + ": " +
                            (detail != nullptr ? detail : document.ErrorName()) +
                            " (truncated or hand-edited file?)");
  }
  const tinyxml2::XMLElement* root = document.RootElement();
  if (root == nullptr || std::string_view(root->Name()) != "VTKFile") {
    throw IoError(path, "not a VTK XML file: the root element is not <VTKFile>");
  }
  const char* root_type = root->Attribute("type");
  if (root_type == nullptr || std::string_view(root_type) != type) {
    throw IoError(path, "the VTKFile type is " +
                            describe_token(root_type != nullptr ? root_type : "") + "; " +
                            std::string(wrong_type_hint));
  }
  return *root;
}

const tinyxml2::XMLElement& required_child(const std::filesystem::path& path,
                                           const tinyxml2::XMLElement& parent, const char* name) {
  const tinyxml2::XMLElement* child = parent.FirstChildElement(name);
  if (child == nullptr) {
    throw IoError(path, at_line(parent) + "<" + parent.Name() + "> has no <" + name + ">");
  }
  return *child;
}

std::vector<const tinyxml2::XMLElement*> poly_data_pieces(const std::filesystem::path& path,
                                                          const tinyxml2::XMLElement& root) {
  const tinyxml2::XMLElement& poly_data = required_child(path, root, "PolyData");
  std::vector<const tinyxml2::XMLElement*> pieces;
  for (const auto* piece = poly_data.FirstChildElement("Piece"); piece != nullptr;
       piece = piece->NextSiblingElement("Piece")) {
    pieces.push_back(piece);
  }
  if (pieces.empty()) required_child(path, poly_data, "Piece");  // throws "has no <Piece>"
  return pieces;
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

void read_points(const std::filesystem::path& path, const tinyxml2::XMLElement& piece,
                 std::int64_t num_points, const std::string& piece_label,
                 std::vector<double>& coordinates) {
  const auto base = static_cast<std::int64_t>(coordinates.size() / 3);
  if (base + num_points > INT_MAX) {
    throw IoError(path, at_line(piece) + "more points than a 32-bit index can address");
  }
  if (num_points == 0) return;
  const tinyxml2::XMLElement* points = piece.FirstChildElement("Points");
  const tinyxml2::XMLElement* array =
      points != nullptr ? points->FirstChildElement("DataArray") : nullptr;
  if (array == nullptr) {
    throw IoError(path, at_line(piece) + piece_label + " announces " + std::to_string(num_points) +
                            " points but has no <Points><DataArray>");
  }
  check_ascii_array(path, *array, "Points", false);
  const int components = array->IntAttribute("NumberOfComponents", 1);
  if (components != 3) {
    throw IoError(path, at_line(*array) + "the Points DataArray has NumberOfComponents=" +
                            std::to_string(components) + ", expected 3");
  }
  const std::vector<double> values = parse_reals(path, *array, "Points");
  if (static_cast<std::int64_t>(values.size()) != 3 * num_points) {
    throw IoError(path, at_line(*array) + piece_label + " Points DataArray holds " +
                            std::to_string(values.size()) + " numbers, expected 3 x " +
                            std::to_string(num_points) + " (NumberOfPoints)");
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw IoError(path, at_line(*array) + piece_label + " point " + std::to_string(i / 3) +
                              " has a non-finite coordinate (NaN or inf)");
    }
  }
  coordinates.insert(coordinates.end(), values.begin(), values.end());
}

Cells read_cells(const std::filesystem::path& path, const tinyxml2::XMLElement& piece,
                 const char* section_name, std::int64_t num_cells, std::int64_t num_points,
                 std::int64_t base, int min_points, const std::string& piece_label) {
  Cells cells;
  const tinyxml2::XMLElement* section = piece.FirstChildElement(section_name);
  if (section == nullptr) {
    if (num_cells == 0) return cells;
    throw IoError(path, at_line(piece) + piece_label + " announces " + std::to_string(num_cells) +
                            " " + section_name + " but has no <" + section_name + "> element");
  }
  const std::string label = piece_label + " " + section_name;
  const tinyxml2::XMLElement* connectivity_array = named_array(*section, "connectivity");
  const tinyxml2::XMLElement* offsets_array = named_array(*section, "offsets");
  if (connectivity_array == nullptr || offsets_array == nullptr) {
    throw IoError(
        path, at_line(*section) + label + " needs DataArrays named 'connectivity' and 'offsets'");
  }
  check_ascii_array(path, *connectivity_array, section_name, true);
  check_ascii_array(path, *offsets_array, section_name, true);
  const std::vector<std::int64_t> connectivity =
      parse_integers(path, *connectivity_array, section_name);
  std::vector<std::int64_t> offsets = parse_integers(path, *offsets_array, section_name);
  // VTK writes one end offset per cell; a leading 0 (in-memory layout of
  // VTK 9) is accepted too.
  if (static_cast<std::int64_t>(offsets.size()) == num_cells + 1 && !offsets.empty() &&
      offsets.front() == 0) {
    offsets.erase(offsets.begin());
  }
  if (static_cast<std::int64_t>(offsets.size()) != num_cells) {
    throw IoError(path, at_line(*offsets_array) + label + " offsets hold " +
                            std::to_string(offsets.size()) + " values but the Piece announces " +
                            std::to_string(num_cells) + " cells");
  }
  const std::int64_t total = offsets.empty() ? 0 : offsets.back();
  if (total != static_cast<std::int64_t>(connectivity.size())) {
    throw IoError(path, at_line(*offsets_array) + label + " last offset is " +
                            std::to_string(total) + " but connectivity holds " +
                            std::to_string(connectivity.size()) + " indices");
  }
  cells.indices.reserve(connectivity.size());
  cells.ends.reserve(offsets.size());
  std::int64_t start = 0;
  for (std::size_t c = 0; c < offsets.size(); ++c) {
    const std::int64_t end = offsets[c];
    if (end - start < min_points) {
      throw IoError(path, at_line(*offsets_array) + label + " cell " + std::to_string(c) + " has " +
                              std::to_string(std::max<std::int64_t>(end - start, 0)) +
                              " points (offsets must increase by at least " +
                              std::to_string(min_points) + ")");
    }
    if (end > static_cast<std::int64_t>(connectivity.size())) {
      throw IoError(path, at_line(*offsets_array) + label + " cell " + std::to_string(c) +
                              " ends at offset " + std::to_string(end) +
                              " but the connectivity holds " + std::to_string(connectivity.size()) +
                              " entries");
    }
    for (std::int64_t k = start; k < end; ++k) {
      const std::int64_t index = connectivity[static_cast<std::size_t>(k)];
      if (index < 0 || index >= num_points) {
        throw IoError(path, at_line(*connectivity_array) + label + " cell " + std::to_string(c) +
                                " refers to point " + std::to_string(index) +
                                " but the piece has " + std::to_string(num_points) + " points");
      }
      cells.indices.push_back(static_cast<int>(base + index));
    }
    cells.ends.push_back(cells.indices.size());
    start = end;
  }
  return cells;
}

std::string xml_escape(std::string_view text) {
  std::string escaped;
  escaped.reserve(text.size());
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

void check_arrays(const NamedScalars& arrays, Eigen::Index expected, const ArrayOwner& owner,
                  const std::filesystem::path& path) {
  std::set<std::string> names;
  for (const auto& [name, values] : arrays) {
    check_array(name, values, expected, owner, path);
    if (!names.insert(name).second) {
      throw InvalidInputError("cannot write " + path.string() + ": " + owner.kind + " array '" +
                              name + "' appears twice (names must be unique)");
    }
  }
}

void append_header(std::string& out) {
  out +=
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <PolyData>\n";
}

void append_piece_start(std::string& out, Eigen::Index num_points, Eigen::Index num_lines,
                        Eigen::Index num_polys) {
  out += R"(    <Piece NumberOfPoints=")";
  out += std::to_string(num_points);
  out += R"(" NumberOfVerts="0" NumberOfLines=")";
  out += std::to_string(num_lines);
  out += R"(" NumberOfStrips="0" NumberOfPolys=")";
  out += std::to_string(num_polys);
  out += "\">\n";
}

void append_scalar_arrays(std::string& out, const char* tag, const NamedScalars& arrays) {
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

void append_points(std::string& out, const Eigen::MatrixX3d& points) {
  out +=
      "      <Points>\n"
      "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
      "format=\"ascii\">\n";
  for (Eigen::Index v = 0; v < points.rows(); ++v) {
    out += "          ";
    for (Eigen::Index k = 0; k < 3; ++k) {
      if (k > 0) out += ' ';
      io_detail::append_number(out, points(v, k));
    }
    out += '\n';
  }
  out +=
      "        </DataArray>\n"
      "      </Points>\n";
}

void append_wrapped_integers(std::string& out, const std::vector<std::int64_t>& values,
                             std::size_t per_line) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += (i % per_line == 0) ? "          " : " ";
    io_detail::append_number(out, values[i]);
    if (i % per_line == per_line - 1 || i + 1 == values.size()) out += '\n';
  }
}

void append_footer(std::string& out) {
  out +=
      "    </Piece>\n"
      "  </PolyData>\n"
      "</VTKFile>\n";
}

}  // namespace mmm::mesh::vtk_detail

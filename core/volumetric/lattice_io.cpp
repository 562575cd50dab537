#include "core/volumetric/lattice_io.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "core/file_bytes.h"

namespace mmm::volumetric {
namespace {

constexpr std::array<char, 8> kMagic = {'M', 'M', 'M', 'L', 'A', 'T', '1', '\n'};

struct Header {
  std::array<double, 3> origin{};
  double spacing = 0.0;
  std::array<std::int32_t, 3> cells{};
  std::uint32_t muscles = 0;
};
constexpr std::uint64_t kHeaderBytes =
    kMagic.size() + 4 * sizeof(double) + 3 * sizeof(std::int32_t) + sizeof(std::uint32_t);

template <typename T>
void append(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

void append_labels(std::string& out, const LabelledLattice& lattice) {
  out.append(reinterpret_cast<const char*>(lattice.label.data()),
             lattice.label.size() * sizeof(std::uint16_t));
}

template <typename T>
T take(const std::string& bytes, std::size_t& at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  at += sizeof(T);
  return value;
}

}  // namespace

void write_lattice(const std::filesystem::path& path, const LabelledLattice& lattice) {
  std::string bytes(kMagic.begin(), kMagic.end());
  for (int axis = 0; axis < 3; ++axis) append(bytes, lattice.origin[axis]);
  append(bytes, lattice.spacing_mm);
  for (int axis = 0; axis < 3; ++axis)
    append(bytes, static_cast<std::int32_t>(lattice.cells[axis]));
  append(bytes, static_cast<std::uint32_t>(lattice.muscles.size()));
  append_labels(bytes, lattice);
  write_file_atomically(path, bytes, "a lattice file");
}

LabelledLattice read_lattice(const std::filesystem::path& path, std::int64_t max_cells) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) throw IoError(path, "cannot be read (" + error.message() + ")");
  if (size > kHeaderBytes + static_cast<std::uintmax_t>(max_cells) * sizeof(std::uint16_t)) {
    throw IoError(path, "is " + std::to_string(size) + " bytes: more cells than the limit (" +
                            std::to_string(max_cells) + ")");
  }
  const std::string bytes = read_file_bytes(path, size);
  if (size < kHeaderBytes || !std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) {
    throw IoError(path, "is not an mmm lattice (.lattice: it must start with MMMLAT1)");
  }
  std::size_t at = kMagic.size();
  Header h;
  for (double& x : h.origin) x = take<double>(bytes, at);
  h.spacing = take<double>(bytes, at);
  for (std::int32_t& c : h.cells) c = take<std::int32_t>(bytes, at);
  h.muscles = take<std::uint32_t>(bytes, at);
  if (!std::isfinite(h.origin[0]) || !std::isfinite(h.origin[1]) || !std::isfinite(h.origin[2])) {
    throw IoError(path, "has a non-finite origin");
  }
  if (!(h.spacing > 0) || !std::isfinite(h.spacing)) {
    throw IoError(path, "has spacing " + std::to_string(h.spacing) + " mm (must be positive)");
  }
  std::int64_t total = 1;
  for (const std::int32_t c : h.cells) {
    if (c <= 0) throw IoError(path, "has a cell count of " + std::to_string(c) + " along an axis");
    total = total > max_cells ? total : total * c;
  }
  if (total > max_cells) {
    throw IoError(path, "has more cells than the limit (" + std::to_string(max_cells) + ")");
  }
  const std::uint64_t expected =
      kHeaderBytes + static_cast<std::uint64_t>(total) * sizeof(std::uint16_t);
  if (expected != size) {
    throw IoError(path, "is " + std::to_string(size) + " bytes, its header says " +
                            std::to_string(expected) + " (truncated or not a .lattice)");
  }
  LabelledLattice lattice;
  lattice.origin = {h.origin[0], h.origin[1], h.origin[2]};
  lattice.spacing_mm = h.spacing;
  lattice.cells = {h.cells[0], h.cells[1], h.cells[2]};
  lattice.label.resize(static_cast<std::size_t>(total));
  std::memcpy(lattice.label.data(), bytes.data() + at,
              lattice.label.size() * sizeof(std::uint16_t));
  for (std::size_t c = 0; c < lattice.label.size(); ++c) {
    if (lattice.label[c] > h.muscles) {
      throw IoError(path, "cell " + std::to_string(c) + " has label " +
                              std::to_string(lattice.label[c]) + ", the lattice has " +
                              std::to_string(h.muscles) + " muscles");
    }
  }
  return lattice;
}

void write_lattice_vti(const std::filesystem::path& path, const LabelledLattice& lattice) {
  std::ostringstream xml;
  xml.precision(17);
  const Eigen::Array3i& n = lattice.cells;
  xml << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n"
      << "  <ImageData WholeExtent=\"0 " << n.x() << " 0 " << n.y() << " 0 " << n.z()
      << "\" Origin=\"" << lattice.origin.x() << " " << lattice.origin.y() << " "
      << lattice.origin.z() << "\" Spacing=\"" << lattice.spacing_mm << " " << lattice.spacing_mm
      << " " << lattice.spacing_mm << "\">\n"
      << "    <Piece Extent=\"0 " << n.x() << " 0 " << n.y() << " 0 " << n.z() << "\">\n"
      << "      <CellData Scalars=\"muscle\">\n"
      << "        <DataArray type=\"UInt16\" Name=\"muscle\" format=\"appended\" offset=\"0\"/>\n"
      << "      </CellData>\n"
      << "    </Piece>\n"
      << "  </ImageData>\n"
      << "  <AppendedData encoding=\"raw\">\n   _";
  std::string bytes = xml.str();
  append(bytes, static_cast<std::uint64_t>(lattice.label.size() * sizeof(std::uint16_t)));
  append_labels(bytes, lattice);
  bytes += "\n  </AppendedData>\n</VTKFile>\n";
  write_file_atomically(path, bytes, "a lattice image");
}

}  // namespace mmm::volumetric

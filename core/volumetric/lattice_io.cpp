#include "core/volumetric/lattice_io.h"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "core/errors.h"

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
void put(std::ofstream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

std::ofstream open_for_writing(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw IoError(path, "cannot be written");
  return out;
}

void put_labels(std::ofstream& out, const LabelledLattice& lattice) {
  out.write(reinterpret_cast<const char*>(lattice.label.data()),
            static_cast<std::streamsize>(lattice.label.size() * sizeof(std::uint16_t)));
}

void finish(std::ofstream& out, const std::filesystem::path& path) {
  out.flush();
  if (!out) throw IoError(path, "could not be written in full (disk full?)");
}

}  // namespace

void write_lattice(const std::filesystem::path& path, const LabelledLattice& lattice) {
  std::ofstream out = open_for_writing(path);
  out.write(kMagic.data(), kMagic.size());
  for (int axis = 0; axis < 3; ++axis) put(out, lattice.origin[axis]);
  put(out, lattice.spacing_mm);
  for (int axis = 0; axis < 3; ++axis) put(out, static_cast<std::int32_t>(lattice.cells[axis]));
  put(out, static_cast<std::uint32_t>(lattice.muscles.size()));
  put_labels(out, lattice);
  finish(out, path);
}

LabelledLattice read_lattice(const std::filesystem::path& path, std::int64_t max_cells) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) throw IoError(path, "cannot be read (" + error.message() + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, "cannot be opened");
  std::array<char, 8> magic{};
  Header h;
  const bool read = size >= kHeaderBytes && in.read(magic.data(), magic.size()) &&
                    magic == kMagic &&
                    in.read(reinterpret_cast<char*>(h.origin.data()), sizeof(h.origin)) &&
                    in.read(reinterpret_cast<char*>(&h.spacing), sizeof(h.spacing)) &&
                    in.read(reinterpret_cast<char*>(h.cells.data()), sizeof(h.cells)) &&
                    in.read(reinterpret_cast<char*>(&h.muscles), sizeof(h.muscles));
  if (!read) throw IoError(path, "is not an mmm lattice (.lattice: it must start with MMMLAT1)");
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
  if (!in.read(reinterpret_cast<char*>(lattice.label.data()),
               static_cast<std::streamsize>(lattice.label.size() * sizeof(std::uint16_t)))) {
    throw IoError(path, "could not be read in full");
  }
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
  std::ofstream out = open_for_writing(path);
  out << xml.str();
  put(out, static_cast<std::uint64_t>(lattice.label.size() * sizeof(std::uint16_t)));
  put_labels(out, lattice);
  out << "\n  </AppendedData>\n</VTKFile>\n";
  finish(out, path);
}

}  // namespace mmm::volumetric

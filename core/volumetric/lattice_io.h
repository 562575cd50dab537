#pragma once
// Files of a labelled lattice (labelled_lattice.h): the volumetric model at
// rest is its labels, and its tetrahedra follow from them (lattice_tets.h,
// tens of milliseconds), so the study keeps the labels only.
//
//   .lattice  mmm's own binary, read back by later nodes: "MMMLAT1\n", then
//             little-endian float64 origin x, y, z and spacing (mm), int32
//             cells x, y, z, uint32 number of muscles, and one uint16 label
//             per cell (x fastest, then y, then z; 0 empty, k + 1 the k-th
//             muscle). Read back exactly; the per-muscle report is not in it.
//   .vti      VTK XML ImageData (raw appended binary) for ParaView: the cells
//             with a cell array "muscle" (the label); Threshold shows one muscle.

#include <cstdint>
#include <filesystem>

#include "core/volumetric/labelled_lattice.h"

namespace mmm::volumetric {

// Written atomically (core/file_bytes.h). Throws IoError when the file cannot
// be written.
void write_lattice(const std::filesystem::path& path, const LabelledLattice& lattice);

// Throws IoError (path first) for a missing file, a file larger than
// max_cells labels need (checked before it is read), a file that is not a
// .lattice (magic), a non-finite origin, a non-positive spacing, a
// non-positive cell count or more cells than max_cells, a size that
// disagrees with the header, or a label above the number of muscles.
LabelledLattice read_lattice(const std::filesystem::path& path,
                             std::int64_t max_cells = 200'000'000);

// Written atomically. Throws IoError when the file cannot be written.
void write_lattice_vti(const std::filesystem::path& path, const LabelledLattice& lattice);

}  // namespace mmm::volumetric

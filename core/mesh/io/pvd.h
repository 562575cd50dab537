#pragma once
// ParaView collection files (.pvd): an index of data files by time step and
// part, which ParaView plays as an animation (one .vtp per part and frame).
//
//   <?xml version="1.0"?>
//   <VTKFile type="Collection" version="0.1" byte_order="LittleEndian">
//     <Collection>
//       <DataSet timestep="0.5" group="" part="0" file="walk/femur_r_0000.vtp" name="femur_r"/>
//     </Collection>
//   </VTKFile>

#include <filesystem>
#include <string>
#include <vector>

namespace mmm::mesh {

// One data file of a collection.
//   time  time step (s for gait trials); finite
//   file  path relative to the .pvd's folder, inside it (no "..")
//   part  parts shown together at one time step are numbered 0, 1, ...
//   name  the part's name in ParaView's pipeline browser (ParaView >= 5.5);
//         written only when non-empty
struct PvdEntry {
  double time = 0.0;
  std::filesystem::path file;
  int part = 0;
  std::string name;
};

// Writes the entries in the given order (times with shortest round-trip text,
// file paths with '/' separators, attributes XML-escaped), atomically
// (temporary sibling + rename). The data files are not checked for existence.
// Throws InvalidInputError ("cannot write <path>: entry 3 ...") for a
// non-finite time, a negative part, an empty or absolute file path or one that
// leaves the .pvd's folder through ".."; IoError when the file cannot be
// written.
void write_pvd(const std::vector<PvdEntry>& entries, const std::filesystem::path& path);

// Reads the <DataSet> elements of a <VTKFile type="Collection"> in file order.
// part defaults to 0 and name to "" when absent; file is returned as written
// (relative to the .pvd's folder; an absolute path written by another tool is
// kept as is). Throws IoError (path first) for a missing or empty file,
// malformed XML (with the line), another VTKFile type, no <Collection>, or a
// DataSet without a file or with a timestep / part that is not a finite
// number / a non-negative integer.
std::vector<PvdEntry> read_pvd(const std::filesystem::path& path);

}  // namespace mmm::mesh

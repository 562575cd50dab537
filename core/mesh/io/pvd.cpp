#include "core/mesh/io/pvd.h"

#include <tinyxml2.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>

#include "core/errors.h"
#include "core/mesh/io/io_common.h"
#include "core/mesh/io/vtp_common.h"

namespace mmm::mesh {

namespace {

using io_detail::describe_token;

// A collection must stay movable as a whole folder: every file lies below the
// .pvd's folder, named relative to it.
void check_entry(const PvdEntry& entry, std::size_t index, const std::filesystem::path& path) {
  const std::string where = "cannot write " + path.string() + ": entry " + std::to_string(index);
  if (!std::isfinite(entry.time)) {
    throw InvalidInputError(where +
                            " has a non-finite time (NaN or inf); ParaView orders "
                            "time steps by value");
  }
  if (entry.part < 0) {
    throw InvalidInputError(where + " has part " + std::to_string(entry.part) +
                            "; parts are numbered from 0");
  }
  if (entry.file.empty()) throw InvalidInputError(where + " has an empty file path");
  if (entry.file.has_root_path()) {
    throw InvalidInputError(where + " file '" + entry.file.string() +
                            "' is absolute; give it relative to the .pvd's folder so that the "
                            "folder can be moved");
  }
  const std::filesystem::path normal = entry.file.lexically_normal();
  if (normal.empty() || *normal.begin() == ".." || normal == ".") {
    throw InvalidInputError(where + " file '" + entry.file.string() +
                            "' does not name a file inside the .pvd's folder (no '..' above it)");
  }
}

double read_time(const std::filesystem::path& path, const tinyxml2::XMLElement& data_set) {
  const char* text = data_set.Attribute("timestep");
  if (text == nullptr) {
    throw IoError(path, vtk_detail::at_line(data_set) + "<DataSet> has no timestep attribute");
  }
  double time = 0.0;
  if (!io_detail::parse_double(text, time) || !std::isfinite(time)) {
    throw IoError(path, vtk_detail::at_line(data_set) + "<DataSet> timestep=" +
                            describe_token(text) + " is not a finite number");
  }
  return time;
}

int read_part(const std::filesystem::path& path, const tinyxml2::XMLElement& data_set) {
  const char* text = data_set.Attribute("part");
  if (text == nullptr) return 0;
  std::int64_t part = 0;
  if (!io_detail::parse_int(text, part) || part < 0 || part > std::numeric_limits<int>::max()) {
    throw IoError(path, vtk_detail::at_line(data_set) + "<DataSet> part=" + describe_token(text) +
                            " is not a non-negative integer");
  }
  return static_cast<int>(part);
}

}  // namespace

void write_pvd(const std::vector<PvdEntry>& entries, const std::filesystem::path& path) {
  for (std::size_t i = 0; i < entries.size(); ++i) check_entry(entries[i], i, path);
  std::string out =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (const PvdEntry& entry : entries) {
    out += R"(    <DataSet timestep=")";
    io_detail::append_number(out, entry.time);
    out += R"(" group="" part=")";
    out += std::to_string(entry.part);
    out += R"(" file=")";
    out += vtk_detail::xml_escape(entry.file.generic_string());
    if (!entry.name.empty()) {
      out += R"(" name=")";
      out += vtk_detail::xml_escape(entry.name);
    }
    out += "\"/>\n";
  }
  out +=
      "  </Collection>\n"
      "</VTKFile>\n";
  io_detail::write_file_atomically(path, out);
}

std::vector<PvdEntry> read_pvd(const std::filesystem::path& path) {
  tinyxml2::XMLDocument document;
  const tinyxml2::XMLElement& root = vtk_detail::load_vtk_file(
      path, document, "Collection", "a .pvd index has type \"Collection\"");
  const tinyxml2::XMLElement& collection = vtk_detail::required_child(path, root, "Collection");
  std::vector<PvdEntry> entries;
  for (const auto* data_set = collection.FirstChildElement("DataSet"); data_set != nullptr;
       data_set = data_set->NextSiblingElement("DataSet")) {
    const char* file = data_set->Attribute("file");
    if (file == nullptr || *file == '\0') {
      throw IoError(path, vtk_detail::at_line(*data_set) + "<DataSet> has no file attribute");
    }
    const char* name = data_set->Attribute("name");
    entries.push_back(PvdEntry{read_time(path, *data_set), std::filesystem::path(file),
                               read_part(path, *data_set), name != nullptr ? name : ""});
  }
  return entries;
}

}  // namespace mmm::mesh

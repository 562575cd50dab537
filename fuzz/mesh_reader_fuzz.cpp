// Mesh readers: STL, PLY, OBJ, OFF, VTP (read_mesh picks by extension).
#include <exception>
#include <string>

#include "core/mesh/io/mesh_io.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"

namespace mmm::fuzz {
namespace {

void read_as(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  const auto path = as_file(data, size, "input" + extension);
  try {
    (void)mesh::read_mesh(path);
  } catch (const std::exception&) {
  }
}

}  // namespace

void stl(const std::uint8_t* data, std::size_t size) { read_as(data, size, ".stl"); }
void ply(const std::uint8_t* data, std::size_t size) { read_as(data, size, ".ply"); }
void obj(const std::uint8_t* data, std::size_t size) { read_as(data, size, ".obj"); }
void off(const std::uint8_t* data, std::size_t size) { read_as(data, size, ".off"); }
void vtp(const std::uint8_t* data, std::size_t size) { read_as(data, size, ".vtp"); }

}  // namespace mmm::fuzz

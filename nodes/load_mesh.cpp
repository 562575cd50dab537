#include "nodes/load_mesh.h"

#include <string>

#include "core/errors.h"
#include "core/mesh/io/obj.h"
#include "core/mesh/io/off.h"
#include "core/mesh/io/ply.h"
#include "core/mesh/io/stl.h"
#include "core/mesh/io/vtp.h"

namespace mmm::nodes {
namespace {

// Scale factors outside this range are typos, not unit conversions (um to mm
// is 1e-3, km to mm is 1e6). 1e-4 rather than a smaller bound: it prints as
// "0.0001" in range messages.
constexpr double kMinScale = 1e-4;
constexpr double kMaxScale = 1e6;

mesh::IndexedMesh read_as(const std::filesystem::path& file, const std::string& format) {
  if (format == "stl") return mesh::read_stl(file);
  if (format == "obj") return mesh::read_obj(file);
  if (format == "ply") return mesh::read_ply(file);
  if (format == "off") return mesh::read_off(file);
  if (format == "vtp") return mesh::read_vtp(file);
  throw InvalidInputError("load_mesh: unknown format '" + format +
                          "'; expected stl, obj, ply, off or vtp");
}

}  // namespace

workflow::NodeSpec LoadMesh::spec() {
  using workflow::port::File;
  using workflow::port::Mesh;
  return workflow::NodeSpec{"load_mesh", 1, "Read a surface mesh file into a Mesh (mm)"}
      .input<File>("file", "The mesh file (STL, OBJ, PLY, OFF or VTP)")
      .param_enum("format", "stl", {"stl", "obj", "ply", "off", "vtp"}, "Format of the file")
      .param<double>("scale", 1.0, "Multiply coordinates to get mm (1000 for files in metres)",
                     {.min = kMinScale, .max = kMaxScale})
      .output<Mesh>("mesh", "The surface, coordinates in mm");
}

void LoadMesh::run(workflow::NodeContext& context) {
  const std::string& format = context.text("format");
  mesh::IndexedMesh surface = read_as(context.input("file").path, format);
  const double scale = context.number("scale");
  if (scale != 1.0) surface.V *= scale;
  context.info("read " + std::to_string(surface.num_vertices()) + " vertices, " +
               std::to_string(surface.num_faces()) + " faces (" + format + ")");
  const std::filesystem::path out = context.scratch_dir() / "mesh.ply";
  mesh::write_ply(surface, out);
  context.set_output_file("mesh", out);
}

}  // namespace mmm::nodes

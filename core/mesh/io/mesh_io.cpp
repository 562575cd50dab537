#include "core/mesh/io/mesh_io.h"

#include <string>

#include "core/errors.h"
#include "core/mesh/io/io_common.h"
#include "core/mesh/io/obj.h"
#include "core/mesh/io/off.h"
#include "core/mesh/io/ply.h"
#include "core/mesh/io/stl.h"
#include "core/mesh/io/vtp.h"

namespace mmm::mesh {

MeshFormat format_from_extension(const std::filesystem::path& path) {
  const std::string extension = io_detail::to_lower(path.extension().string());
  if (extension == ".stl") return MeshFormat::kStl;
  if (extension == ".obj") return MeshFormat::kObj;
  if (extension == ".ply") return MeshFormat::kPly;
  if (extension == ".off") return MeshFormat::kOff;
  if (extension == ".vtp") return MeshFormat::kVtp;
  const std::string what =
      extension.empty() ? std::string("has no file extension")
                        : "has the unknown mesh extension '" + path.extension().string() + "'";
  throw IoError(path, what + "; supported: .stl .obj .ply .off .vtp");
}

IndexedMesh read_mesh(const std::filesystem::path& path) {
  // The file checks come first: "no such file" says more than an extension
  // complaint about a path that does not exist.
  io_detail::check_mesh_file(path);
  switch (format_from_extension(path)) {
    case MeshFormat::kStl:
      return read_stl(path);
    case MeshFormat::kObj:
      return read_obj(path);
    case MeshFormat::kPly:
      return read_ply(path);
    case MeshFormat::kOff:
      return read_off(path);
    case MeshFormat::kVtp:
      return read_vtp(path);
  }
  throw IoError(path, "internal error: unhandled mesh format");
}

void write_mesh(const IndexedMesh& mesh, const std::filesystem::path& path,
                const WriteOptions& options) {
  switch (format_from_extension(path)) {
    case MeshFormat::kStl:
      write_stl(mesh, path, StlWriteOptions{.ascii = options.ascii});
      return;
    case MeshFormat::kObj:
      write_obj(mesh, path);
      return;
    case MeshFormat::kPly:
      write_ply(mesh, path, PlyWriteOptions{.ascii = options.ascii});
      return;
    case MeshFormat::kOff:
      write_off(mesh, path);
      return;
    case MeshFormat::kVtp:
      write_vtp(mesh, path);
      return;
  }
  throw IoError(path, "internal error: unhandled mesh format");
}

}  // namespace mmm::mesh

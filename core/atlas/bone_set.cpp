#include "core/atlas/bone_set.h"

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "core/bounded_yaml.h"
#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"

namespace mmm::atlas {
namespace {

constexpr std::uintmax_t kMaxSurfaceBytes = std::uintmax_t{1} << 30;

[[noreturn]] void fail(const std::filesystem::path& manifest, const std::string& message) {
  throw IoError(manifest, message);
}

Eigen::Vector3d read_point(const std::filesystem::path& manifest, const YAML::Node& node,
                           const std::string& field) {
  if (!node.IsSequence() || node.size() != 3) {
    fail(manifest, "field '" + field + "' must be a list of 3 numbers");
  }
  Eigen::Vector3d point;
  for (int i = 0; i < 3; ++i) {
    try {
      point[i] = node[static_cast<std::size_t>(i)].as<double>();
    } catch (const YAML::Exception&) {
      fail(manifest, "field '" + field + "' must be a list of 3 numbers");
    }
    if (!std::isfinite(point[i])) fail(manifest, "field '" + field + "' is not finite");
  }
  return point;
}

Eigen::Affine3d read_transform(const std::filesystem::path& manifest, const YAML::Node& node) {
  const std::string hint = "field 'transform' must be 4 rows of 4 finite numbers (row-major)";
  if (!node.IsSequence() || node.size() != 4) fail(manifest, hint);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    const YAML::Node row = node[static_cast<std::size_t>(r)];
    if (!row.IsSequence() || row.size() != 4) fail(manifest, hint);
    for (int c = 0; c < 4; ++c) {
      try {
        m(r, c) = row[static_cast<std::size_t>(c)].as<double>();
      } catch (const YAML::Exception&) {
        fail(manifest, hint);
      }
      if (!std::isfinite(m(r, c))) fail(manifest, hint);
    }
  }
  if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
    fail(manifest, "field 'transform': the last row must be 0 0 0 1 (an affine map)");
  }
  if (std::abs(m.topLeftCorner<3, 3>().determinant()) < 1e-9) {
    fail(manifest, "field 'transform': the linear part is singular");
  }
  Eigen::Affine3d map;
  map.matrix() = m;
  return map;
}

mesh::IndexedMesh read_surface(const std::filesystem::path& manifest,
                               const std::filesystem::path& file, const std::string& field) {
  std::error_code error;
  const std::uintmax_t bytes = std::filesystem::file_size(file, error);
  if (error) fail(manifest, "field '" + field + "': cannot read " + file.string());
  if (bytes > kMaxSurfaceBytes) {
    fail(manifest, "field '" + field + "': " + file.string() + " is larger than 1 GiB");
  }
  try {
    return mesh::read_mesh(file);
  } catch (const std::exception& e) {
    fail(manifest, "field '" + field + "': " + e.what());
  }
}

}  // namespace

BoneSet read_bone_set(const std::filesystem::path& manifest) {
  YAML::Node root;
  try {
    root = load_yaml_file(manifest);
  } catch (const IoError&) {
    throw;
  } catch (const std::exception& e) {
    fail(manifest, std::string("not a valid YAML bone-set manifest: ") + e.what());
  }
  if (!root.IsMap()) fail(manifest, "a bone-set manifest is a mapping (mmm_bone_set: 1, ...)");
  if (!root["mmm_bone_set"] || root["mmm_bone_set"].Scalar() != "1") {
    fail(manifest, "field 'mmm_bone_set' must be 1; hint: start the file with 'mmm_bone_set: 1'");
  }
  for (const auto& entry : root) {
    const std::string key = entry.first.Scalar();
    if (key != "mmm_bone_set" && key != "units" && key != "frame" && key != "transform" &&
        key != "bones" && key != "soft_tissue" && key != "landmarks") {
      fail(manifest, "unknown field '" + key +
                         "'; known: mmm_bone_set, units, frame, transform, bones, soft_tissue, "
                         "landmarks");
    }
  }
  const std::string units = root["units"] ? root["units"].Scalar() : "";
  if (units != "mm" && units != "m") {
    fail(manifest, "field 'units' must be mm or m (the length unit of the surface files)");
  }
  const std::string frame = root["frame"] ? root["frame"].Scalar() : "";
  if (frame != "RAS" && frame != "LPS") {
    fail(manifest,
         "field 'frame' must be RAS (x right, y anterior, z superior) or LPS (x left, y "
         "posterior, z superior, as DICOM)");
  }
  Eigen::Affine3d map = Eigen::Affine3d::Identity();
  if (root["transform"]) map = read_transform(manifest, root["transform"]);
  Eigen::Affine3d convention = Eigen::Affine3d::Identity();
  convention.linear() *= units == "m" ? 1000.0 : 1.0;
  if (frame == "LPS")
    convention.linear() = convention.linear() * Eigen::Vector3d(-1, -1, 1).asDiagonal();
  const Eigen::Affine3d to_patient = map * convention;
  const auto place = [&](mesh::IndexedMesh surface) {
    surface.V = ((surface.V * to_patient.linear().transpose()).rowwise() +
                 to_patient.translation().transpose())
                    .eval();
    if (to_patient.linear().determinant() < 0) surface.F.col(1).swap(surface.F.col(2));
    return surface;
  };
  const std::filesystem::path folder = manifest.parent_path();
  BoneSet set;
  set.source = manifest.string();
  const YAML::Node bones = root["bones"];
  if (!bones || !bones.IsMap() || bones.size() == 0) {
    fail(manifest,
         "field 'bones' must map atlas bone names to surface files (e.g. femur_r: "
         "femur.stl)");
  }
  for (const auto& entry : bones) {
    const std::string name = entry.first.Scalar();
    if (!entry.second.IsScalar()) fail(manifest, "field 'bones." + name + "' must be a file name");
    set.bones[name] =
        place(read_surface(manifest, folder / entry.second.Scalar(), "bones." + name));
  }
  if (const YAML::Node soft = root["soft_tissue"]) {
    if (!soft.IsSequence()) fail(manifest, "field 'soft_tissue' must be a list of file names");
    for (std::size_t i = 0; i < soft.size(); ++i) {
      const std::string field = "soft_tissue[" + std::to_string(i) + "]";
      if (!soft[i].IsScalar()) fail(manifest, "field '" + field + "' must be a file name");
      set.soft_tissue.push_back(place(read_surface(manifest, folder / soft[i].Scalar(), field)));
    }
  }
  if (const YAML::Node landmarks = root["landmarks"]) {
    if (!landmarks.IsMap()) fail(manifest, "field 'landmarks' must map names to [x, y, z]");
    for (const auto& entry : landmarks) {
      const std::string name = entry.first.Scalar();
      set.landmarks[name] = to_patient * read_point(manifest, entry.second, "landmarks." + name);
    }
  }
  return set;
}

void write_bone_set(const BoneSet& set, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  std::ostringstream text;
  text << std::setprecision(17);
  text << "mmm_bone_set: 1\nunits: mm\nframe: RAS\nbones:\n";
  for (const auto& [name, surface] : set.bones) {
    mesh::write_mesh(surface, dir / (name + ".ply"));
    text << "  " << name << ": " << name << ".ply\n";
  }
  if (!set.soft_tissue.empty()) {
    text << "soft_tissue:\n";
    for (std::size_t i = 0; i < set.soft_tissue.size(); ++i) {
      const std::string file = "soft_tissue_" + std::to_string(i) + ".ply";
      mesh::write_mesh(set.soft_tissue[i], dir / file);
      text << "  - " << file << "\n";
    }
  }
  if (!set.landmarks.empty()) {
    text << "landmarks:\n";
    for (const auto& [name, p] : set.landmarks) {
      text << "  " << name << ": [" << p.x() << ", " << p.y() << ", " << p.z() << "]\n";
    }
  }
  std::ofstream out(dir / "manifest.yaml");
  out << text.str();
  if (!out) throw IoError(dir / "manifest.yaml", "cannot write");
}

}  // namespace mmm::atlas

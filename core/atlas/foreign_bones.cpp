#include "core/atlas/foreign_bones.h"

#include <array>
#include <cmath>

#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#include "core/atlas/atlas_io.h"
#include "core/atlas/bone_registration.h"
#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/openmesh_begin.h"
#include "core/mesh/openmesh_end.h"
#include "core/parallel_for.h"

namespace mmm::atlas {
namespace {

struct ForeignBone {
  const char* file;
  const char* bone;
  bool refine;  // one bone in both models: refined by ICP
};

constexpr std::array<ForeignBone, 10> kGait2392Bones = {{
    {"pelvis.vtp", "pelvis", true},
    {"l_pelvis.vtp", "pelvis_l", true},
    {"sacrum.vtp", "sacrum", true},
    {"femur_r.vtp", "femur_r", true},
    {"patella_r.vtp", "patella_r", true},
    {"tibia_r.vtp", "tibia_r", true},
    {"fibula.vtp", "fibula_r", true},
    {"talus.vtp", "talus_r", true},
    {"foot.vtp", "calcn_r", false},
    {"bofoot.vtp", "toes_r", false},
}};

// Two Loop subdivisions: the model's facets (a tibia of 286 triangles) smoothed
// into a surface like a segmented bone's. Open or non-manifold surfaces (the
// hip bones) are kept as they are.
mesh::IndexedMesh smoothed(const mesh::IndexedMesh& surface) {
  mesh::ConversionReport report;
  mesh::Mesh halfedge = mesh::to_halfedge(surface, &report);
  for (const auto& h : halfedge.halfedges()) {
    if (halfedge.is_boundary(h)) return surface;
  }
  if (!report.rejected_faces.empty()) return surface;
  OpenMesh::Subdivider::Uniform::LoopT<mesh::Mesh> loop;
  loop.attach(halfedge);
  loop(2);
  loop.detach();
  return mesh::to_indexed(halfedge);
}

Eigen::MatrixX3d mapped(const Eigen::Affine3d& map, const Eigen::MatrixX3d& v) {
  return ((v * map.linear().transpose()).rowwise() + map.translation().transpose()).eval();
}

}  // namespace

BoneSet gait2392_bone_set(const std::filesystem::path& atlas_dir,
                          const std::filesystem::path& data_dir,
                          const ForeignBoneOptions& options) {
  const Atlas atlas = read_atlas(atlas_dir);
  const PatientDeformation deformation = make_patient_deformation(atlas, options.deformation);
  BoneSet set;
  set.source = "gait2392 bones (" + (data_dir / "gait2392" / "Geometry").string() + ") on atlas " +
               atlas.name + ", patient seed " + std::to_string(options.deformation.seed);
  double reference_scale = 1.0;  // the tibia's, for the foot bones that are not refined
  std::map<std::string, mesh::IndexedMesh> placed;
  for (const ForeignBone& foreign : kGait2392Bones) {
    const Bone* bone = atlas.find_bone(foreign.bone);
    if (bone == nullptr) continue;
    mesh::IndexedMesh surface =
        smoothed(mesh::read_mesh(data_dir / "gait2392" / "Geometry" / foreign.file));
    const mesh::IndexedMesh target = load_mesh(atlas_dir, bone->meshes, "full");
    // Body frame (m) -> atlas (mm) by the bone's frame.
    Eigen::Affine3d frame = bone->frame;
    frame.linear() = frame.linear() * 1000.0;
    surface.V = mapped(frame, surface.V);
    // The scale of the length ratio (the longest side of the oriented box):
    // each bone as long as the atlas's, so that the joints meet as they do in
    // the atlas; its widths and shape stay gait2392's.
    double scale = reference_scale;
    if (foreign.refine) {
      scale = mesh::oriented_bounding_box(target).half_extents.maxCoeff() /
              mesh::oriented_bounding_box(surface).half_extents.maxCoeff();
    }
    if (std::string(foreign.bone) == "tibia_r") reference_scale = scale;
    const Eigen::Vector3d origin = bone->frame.translation();
    Eigen::Affine3d about = Eigen::Affine3d::Identity();
    about.linear() *= scale;
    about.translation() = origin - scale * origin;
    if (foreign.refine) {
      const mesh::AabbTree tree(target);
      RegistrationOptions registration;
      registration.keep_scale = true;
      registration.anisotropic = false;
      about = register_points(surface.V, &tree, {}, about, registration).map;
    }
    surface.V = mapped(about, surface.V);
    placed[foreign.bone] = std::move(surface);
  }
  for (auto& [name, surface] : placed) {
    for (Eigen::Index i = 0; i < surface.V.rows(); ++i) {
      surface.V.row(i) = deformation.map_on_bone(name, surface.V.row(i).transpose()).transpose();
    }
    set.bones[name] = std::move(surface);
  }
  // Soft tissue: the atlas's muscles under the same deformation.
  std::map<std::string, mesh::IndexedMesh> blend_bones;
  for (const Bone& bone : atlas.bones) {
    blend_bones[bone.name] = load_mesh(atlas_dir, bone.meshes, bone.meshes.back().level);
  }
  set.soft_tissue.resize(atlas.muscles.size());
  parallel_for(atlas.muscles.size(), options.threads, [&](std::size_t m) {
    const Muscle& muscle = atlas.muscles[m];
    const bool has_level = std::ranges::any_of(
        muscle.meshes, [&](const MeshLevel& l) { return l.level == options.muscle_level; });
    set.soft_tissue[m] = deform_muscle_mesh(
        deformation, blend_bones,
        load_mesh(atlas_dir, muscle.meshes, has_level ? options.muscle_level : "full"),
        options.deformation.blend_radius_mm);
  });
  return set;
}

}  // namespace mmm::atlas

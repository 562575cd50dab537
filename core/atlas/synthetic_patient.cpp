#include "core/atlas/synthetic_patient.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/atlas/patient_radiographs.h"
#include "core/atlas/structure_carriage.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/image/mesh_render.h"
#include "core/image/png.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/parallel_for.h"

namespace mmm::atlas {
namespace {

// Writes every level of every element (bones, structures, muscles), deformed, under `dir`; returns
// the full-resolution patient meshes (bones, muscles) by name.
struct PatientMeshes {
  std::map<std::string, mesh::IndexedMesh> bones;    // full
  std::map<std::string, mesh::IndexedMesh> muscles;  // `muscle_level`
};

PatientMeshes write_patient_meshes(const Atlas& atlas, const std::filesystem::path& atlas_dir,
                                   const PatientDeformation& deformation,
                                   const std::filesystem::path& dir,
                                   const SyntheticPatientOptions& options) {
  PatientMeshes meshes;
  // Muscles blend the bone maps by distance to the bones: the coarsest bone
  // level is plenty for distances on the scale of the blend radius.
  std::map<std::string, mesh::IndexedMesh> blend_bones;
  for (const Bone& bone : atlas.bones) {
    for (const MeshLevel& level : bone.meshes) {
      const mesh::IndexedMesh deformed =
          deform_bone_mesh(deformation, bone.name, load_mesh(atlas_dir, bone.meshes, level.level));
      std::filesystem::create_directories((dir / level.file).parent_path());
      mesh::write_mesh(deformed, dir / level.file);
      if (level.level == "full") meshes.bones[bone.name] = deformed;
    }
    blend_bones[bone.name] = load_mesh(atlas_dir, bone.meshes, bone.meshes.back().level);
  }
  // Cartilages and ligaments: carried by their bones' maps (structure_carriage.h).
  std::map<std::string, std::unique_ptr<mesh::SignedDistance>> rest_bones;
  for (const Structure& structure : atlas.structures) {
    std::vector<const mesh::SignedDistance*> bones;
    for (const std::string& bone : structure.bones) {
      if (!rest_bones.contains(bone)) {
        rest_bones[bone] = std::make_unique<mesh::SignedDistance>(blend_bones.at(bone));
      }
      bones.push_back(rest_bones.at(bone).get());
    }
    for (const MeshLevel& level : structure.meshes) {
      mesh::IndexedMesh deformed = load_mesh(atlas_dir, structure.meshes, level.level);
      const Eigen::MatrixX3d rest = deformed.V;
      const Eigen::MatrixXd weights = carriage_weights(structure, rest, bones);
      deformed.V.setZero();
      for (Eigen::Index i = 0; i < rest.rows(); ++i) {
        for (std::size_t b = 0; b < structure.bones.size(); ++b) {
          deformed.V.row(i) +=
              weights(i, static_cast<Eigen::Index>(b)) *
              deformation.map_on_bone(structure.bones[b], rest.row(i).transpose()).transpose();
        }
      }
      std::filesystem::create_directories((dir / level.file).parent_path());
      mesh::write_mesh(deformed, dir / level.file);
    }
  }
  // Muscles on `options.threads` threads, each writing its own files; the
  // kept surfaces are gathered in muscle order.
  std::vector<mesh::IndexedMesh> kept(atlas.muscles.size());
  parallel_for(atlas.muscles.size(), options.threads, [&](std::size_t m) {
    const Muscle& muscle = atlas.muscles[m];
    // The level kept: options.muscle_level when the muscle has it, else full.
    const bool has_level = std::ranges::any_of(
        muscle.meshes, [&](const MeshLevel& l) { return l.level == options.muscle_level; });
    const std::string keep = has_level ? options.muscle_level : "full";
    for (const MeshLevel& level : muscle.meshes) {
      mesh::IndexedMesh deformed = deform_muscle_mesh(
          deformation, blend_bones, load_mesh(atlas_dir, muscle.meshes, level.level),
          options.deformation.blend_radius_mm);
      std::filesystem::create_directories((dir / level.file).parent_path());
      mesh::write_mesh(deformed, dir / level.file);
      if (level.level == keep) kept[m] = std::move(deformed);
    }
  });
  for (std::size_t m = 0; m < atlas.muscles.size(); ++m) {
    meshes.muscles[atlas.muscles[m].name] = std::move(kept[m]);
  }
  return meshes;
}

nlohmann::json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

SyntheticPatientReport make_synthetic_patient(const std::filesystem::path& atlas_dir,
                                              const std::filesystem::path& out_dir,
                                              const SyntheticPatientOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  if (!(options.detector_pixel_pitch_mm > 0) || !(options.field_margin_mm >= 0) ||
      !(options.mu_bone_per_mm >= 0) || !(options.mu_soft_per_mm >= 0)) {
    throw InvalidInputError("patient synth: pixel pitch must be > 0, margin and attenuations >= 0");
  }
  const Atlas atlas = read_atlas(atlas_dir);
  const PatientDeformation deformation = make_patient_deformation(atlas, options.deformation);
  Atlas patient = deform_atlas(atlas, deformation);
  patient.name = atlas.name + "_patient_" + std::to_string(options.deformation.seed);
  patient.provenance.push_back("synthetic patient of atlas " + atlas.name + ", seed " +
                               std::to_string(options.deformation.seed));

  const std::filesystem::path partial = out_dir.string() + ".partial";
  std::filesystem::remove_all(partial);
  const PatientMeshes meshes =
      write_patient_meshes(atlas, atlas_dir, deformation, partial / "atlas", options);
  write_atlas_manifest(patient, partial / "atlas");

  PatientRadiographOptions pictures;
  pictures.source_to_isocentre_mm = options.source_to_isocentre_mm;
  pictures.source_to_detector_mm = options.source_to_detector_mm;
  pictures.detector_pixel_pitch_mm = options.detector_pixel_pitch_mm;
  pictures.field_margin_mm = options.field_margin_mm;
  pictures.mu_bone_per_mm = options.mu_bone_per_mm;
  pictures.mu_soft_per_mm = options.mu_soft_per_mm;
  pictures.soft_tissue_envelope = options.soft_tissue_envelope;
  pictures.model = options.model;
  pictures.write_dicom = options.write_dicom;
  pictures.radiograph = options.radiograph;
  pictures.seed = options.deformation.seed;
  pictures.threads = options.threads;
  const std::array<image::RadiographView, 2> views =
      write_patient_radiographs(meshes.bones, meshes.muscles, partial / "radiographs", pictures);

  nlohmann::json truth;
  truth["format"] = "mmm-synthetic-patient";
  truth["version"] = 1;
  truth["atlas"] = atlas.name;
  truth["seed"] = deformation.factors.seed;
  truth["height_mm"] = deformation.factors.height_mm;
  truth["stature_scale"] = deformation.factors.stature_scale;
  truth["pelvis_width"] = deformation.factors.pelvis_width;
  truth["neck_angle_deg"] = deformation.factors.neck_angle_deg;
  truth["segment_length"] = deformation.factors.length;
  truth["segment_width"] = deformation.factors.width;
  nlohmann::json landmarks = nlohmann::json::object();
  for (const Landmark& landmark : patient.landmarks) {
    nlohmann::json entry;
    entry["bone"] = landmark.bone;
    entry["position_mm"] = vector_json(landmark.position);
    for (const image::RadiographView& view : views) {
      const Eigen::Vector2d pixel = image::project(view, landmark.position);
      entry["pixels"][view.name] = {pixel.x(), pixel.y()};
    }
    landmarks[landmark.name] = entry;
  }
  truth["landmarks"] = landmarks;
  {
    std::ofstream out(partial / "ground_truth.json");
    out << truth.dump(2) << '\n';
    if (!out) throw IoError(partial / "ground_truth.json", "cannot write");
  }

  replace_directory(partial, out_dir);

  SyntheticPatientReport report;
  report.factors = deformation.factors;
  report.frontal_width = views[0].width;
  report.frontal_height = views[0].height;
  report.pixel_spacing_mm = views[0].pixel_spacing_mm;
  report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

}  // namespace mmm::atlas

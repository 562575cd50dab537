#include "core/atlas/bone_set_patient.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "core/atlas/atlas_io.h"
#include "core/atlas/bone_registration.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/fit/sphere_fit.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/decimate.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/solidify.h"

namespace mmm::atlas {
namespace {

bool has_tag(const Landmark& landmark, const std::string& tag) {
  return std::ranges::find(landmark.tags, tag) != landmark.tags.end();
}

// Every few vertices of a surface, at most `limit` of them.
Eigen::MatrixX3d sample_vertices(const Eigen::MatrixX3d& vertices, Eigen::Index limit) {
  const Eigen::Index step = std::max<Eigen::Index>(1, vertices.rows() / limit);
  Eigen::MatrixX3d out((vertices.rows() + step - 1) / step, 3);
  for (Eigen::Index i = 0, k = 0; i < vertices.rows(); i += step, ++k) out.row(k) = vertices.row(i);
  return out;
}

// The atlas bone registered onto the given one: a rigid fit with the scale of
// the area ratio, then an affine refinement.
Eigen::Affine3d register_atlas_bone(const mesh::IndexedMesh& atlas_bone,
                                    const mesh::IndexedMesh& given, const mesh::AabbTree& tree) {
  const mesh::MassProperties from = mesh::mass_properties(atlas_bone);
  const mesh::MassProperties to = mesh::mass_properties(given);
  // The area ratio's scale: defined for open surfaces (hip bones) too.
  const double scale = std::sqrt(to.area / std::max(from.area, 1e-9));
  Eigen::Affine3d start = Eigen::Affine3d::Identity();
  start.linear() *= scale;
  start.translation() = to.centroid - scale * from.centroid;
  RegistrationOptions options;
  options.keep_scale = true;
  const Eigen::MatrixX3d source = sample_vertices(atlas_bone.V, 4000);
  return register_points(source, &tree, {}, start, options).map;
}

Eigen::Vector3d sphere_centre_near(const mesh::IndexedMesh& given, const mesh::AabbTree& tree,
                                   Eigen::Vector3d centre) {
  for (int round = 0; round < 2; ++round) {
    const double radius = std::sqrt(tree.closest_point(centre).squared_distance);
    std::vector<Eigen::Index> near;
    for (Eigen::Index i = 0; i < given.V.rows(); ++i) {
      if ((given.V.row(i).transpose() - centre).norm() < 1.25 * radius) near.push_back(i);
    }
    if (near.size() < 12) break;
    Eigen::MatrixX3d points(static_cast<Eigen::Index>(near.size()), 3);
    for (std::size_t k = 0; k < near.size(); ++k) {
      points.row(static_cast<Eigen::Index>(k)) = given.V.row(near[k]);
    }
    centre = fit::sphere_fit(points).center;
  }
  return centre;
}

nlohmann::json point_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// The bones as closed surfaces. A broken one (holes, non-manifold edges,
// several pieces: OpenSim's gait2392 pelvis) would render radiographs of
// something other than the surface the fit is measured against (a ray through
// a hole loses the bone); it is replaced by the boundary of the solid it
// encloses, named in `solidified`.
std::map<std::string, mesh::IndexedMesh> closed_bones(const BoneSet& set,
                                                      std::vector<std::string>& solidified) {
  std::map<std::string, mesh::IndexedMesh> bones;
  for (const auto& [name, surface] : set.bones) {
    if (mesh::check_mesh(surface).single_solid()) {
      bones[name] = surface;
      continue;
    }
    // The grid's level set has about 2.5 faces per mm^2: simplified (quadric
    // collapses move it by far less than the grid's spacing).
    mesh::DecimateOptions fewer;
    fewer.target_faces = kSolidifiedFaces;
    bones[name] = mesh::decimate(mesh::solidify(surface, {kSolidifyGridMm, 2}), fewer);
    solidified.push_back(name);
  }
  return bones;
}

}  // namespace

BoneSetPatientReport make_bone_set_patient(const BoneSet& set,
                                           const std::filesystem::path& atlas_dir,
                                           const std::filesystem::path& out_dir,
                                           const PatientRadiographOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  const Atlas atlas = read_atlas(atlas_dir);
  for (const auto& [name, surface] : set.bones) {
    if (atlas.find_bone(name) == nullptr) {
      std::string known;
      for (const Bone& bone : atlas.bones) known += (known.empty() ? "" : ", ") + bone.name;
      std::string message = "bone set " + set.source + ": '" + name;
      message += "' is not a bone of atlas " + atlas.name;
      message += "; hint: name the bones as the atlas does (" + known + ")";
      throw InvalidInputError(message);
    }
    try {
      mesh::validate_indices_and_coordinates(surface);
    } catch (const std::exception& e) {
      throw InvalidInputError("bone set " + set.source + ", bone " + name + ": " + e.what());
    }
  }
  for (const auto& [name, position] : set.landmarks) {
    if (atlas.find_landmark(name) == nullptr) {
      throw InvalidInputError("bone set " + set.source + ": landmark '" + name +
                              "' is not a landmark of atlas " + atlas.name +
                              "; hint: mmm atlas show lists them");
    }
  }

  BoneSetPatientReport report;
  const std::map<std::string, mesh::IndexedMesh> bones = closed_bones(set, report.solidified);

  const std::filesystem::path partial = out_dir.string() + ".partial";
  std::filesystem::remove_all(partial);
  std::filesystem::create_directories(partial / "bones");
  for (const auto& [name, surface] : bones) {
    mesh::write_mesh(surface, partial / "bones" / (name + ".ply"));
  }
  std::map<std::string, mesh::IndexedMesh> soft;
  for (std::size_t i = 0; i < set.soft_tissue.size(); ++i) {
    soft["soft_tissue_" + std::to_string(i)] = set.soft_tissue[i];
  }
  const std::array<image::RadiographView, 2> views =
      write_patient_radiographs(bones, soft, partial / "radiographs", options);

  nlohmann::json landmarks = nlohmann::json::object();
  std::map<std::string, std::unique_ptr<mesh::AabbTree>> trees;
  std::map<std::string, Eigen::Affine3d> registrations;
  for (const Landmark& landmark : atlas.landmarks) {
    const auto bone = bones.find(landmark.bone);
    const auto given = set.landmarks.find(landmark.name);
    if (bone == bones.end() && given == set.landmarks.end()) continue;
    Eigen::Vector3d position;
    std::string from;
    if (given != set.landmarks.end()) {
      position = given->second;
      from = "given";
      ++report.landmarks_given;
    } else {
      if (!trees.contains(landmark.bone)) {
        trees[landmark.bone] = std::make_unique<mesh::AabbTree>(bone->second);
        const Bone& atlas_bone = *atlas.find_bone(landmark.bone);
        registrations[landmark.bone] = register_atlas_bone(
            load_mesh(atlas_dir, atlas_bone.meshes, "full"), bone->second, *trees[landmark.bone]);
      }
      const mesh::AabbTree& tree = *trees.at(landmark.bone);
      position = registrations.at(landmark.bone) * landmark.position;
      if (landmark.name.starts_with("femoral_head_centre")) {
        position = sphere_centre_near(bone->second, tree, position);
        from = "sphere fitted to the femoral head";
      } else if (landmark.name.starts_with("patella_centre")) {
        position = mesh::mass_properties(bone->second).centroid;
        from = "centroid of the patella";
      } else if (has_tag(landmark, "bony")) {
        position = tree.closest_point(position).point;
        from = "atlas landmark registered and put on the surface";
      } else {
        from = "atlas landmark registered";
      }
      ++report.landmarks_derived;
    }
    nlohmann::json entry;
    entry["bone"] = landmark.bone;
    entry["position_mm"] = point_json(position);
    entry["from"] = from;
    for (const image::RadiographView& view : views) {
      const Eigen::Vector2d pixel = image::project(view, position);
      entry["pixels"][view.name] = {pixel.x(), pixel.y()};
    }
    landmarks[landmark.name] = entry;
  }
  nlohmann::json truth;
  truth["format"] = "mmm-bone-set-patient";
  truth["version"] = 1;
  truth["atlas"] = atlas.name;
  truth["source"] = set.source;
  truth["bones"] = nlohmann::json::array();
  for (const auto& [name, surface] : set.bones) truth["bones"].push_back(name);
  truth["solidified"] = report.solidified;
  truth["landmarks"] = landmarks;
  {
    std::ofstream out(partial / "ground_truth.json");
    out << truth.dump(2) << '\n';
    if (!out) throw IoError(partial / "ground_truth.json", "cannot write");
  }
  replace_directory(partial, out_dir);

  report.bones = static_cast<int>(set.bones.size());
  report.frontal_width = views[0].width;
  report.frontal_height = views[0].height;
  report.pixel_spacing_mm = views[0].pixel_spacing_mm;
  report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

}  // namespace mmm::atlas

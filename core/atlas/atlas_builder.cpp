#include "core/atlas/atlas_builder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "core/atlas/action_line_fit.h"
#include "core/atlas/atlas_io.h"
#include "core/atlas/attachment_areas.h"
#include "core/atlas/bone_registration.h"
#include "core/atlas/kinematic_chain.h"
#include "core/atlas/muscle_cleanup.h"
#include "core/atlas/opensim_mapping.h"
#include "core/atlas/structure_build.h"
#include "core/atlas/surface_line.h"
#include "core/atlas/wrap_surfaces.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/fit/sphere_fit.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/decimate.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/remesh.h"
#include "core/mesh/signed_distance.h"
#include "core/mesh/solidify.h"
#include "core/mesh/winding_number.h"
#include "core/opensim/kinematics.h"
#include "core/opensim/marker_set.h"
#include "core/opensim/osim_model.h"
#include "core/parallel_for.h"

namespace mmm::atlas {
namespace {

// OpenSim's ground axes (X forward, Y up, Z right) as atlas axes (x right,
// y anterior, z superior): a cyclic permutation, det +1.
Eigen::Matrix3d ground_axes_in_atlas() {
  Eigen::Matrix3d axes;
  axes << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  return axes;
}

std::filesystem::path data_file(const AtlasBuildOptions& options, const std::string& relative,
                                const std::string& field) {
  std::filesystem::path path = options.data_dir / relative;
  if (!std::filesystem::exists(path)) {
    throw IoError(
        path, "not found (recipe field " + field + "; is the data folder right? pass --data DIR)");
  }
  return path;
}

mesh::IndexedMesh transformed(const mesh::IndexedMesh& surface, const Eigen::Affine3d& map) {
  mesh::IndexedMesh result = surface;
  for (Eigen::Index i = 0; i < result.V.rows(); ++i) {
    result.V.row(i) = (map * Eigen::Vector3d(surface.V.row(i).transpose())).transpose();
  }
  if (map.linear().determinant() < 0) result.F.col(1).swap(result.F.col(2));
  return result;
}

mesh::IndexedMesh mirrored(const mesh::IndexedMesh& surface, double midline_x) {
  Eigen::Affine3d reflection = Eigen::Affine3d::Identity();
  reflection.linear()(0, 0) = -1.0;
  reflection.translation().x() = 2.0 * midline_x;
  return transformed(surface, reflection);
}

mesh::IndexedMesh merged(const std::vector<mesh::IndexedMesh>& parts) {
  mesh::IndexedMesh result;
  Eigen::Index vertices = 0;
  Eigen::Index faces = 0;
  for (const auto& part : parts) {
    vertices += part.V.rows();
    faces += part.F.rows();
  }
  result.V.resize(vertices, 3);
  result.F.resize(faces, 3);
  vertices = 0;
  faces = 0;
  for (const auto& part : parts) {
    result.V.middleRows(vertices, part.V.rows()) = part.V;
    result.F.middleRows(faces, part.F.rows()) = part.F.array() + static_cast<int>(vertices);
    vertices += part.V.rows();
    faces += part.F.rows();
  }
  return result;
}

Eigen::MatrixX3d vertices_of(const std::vector<mesh::IndexedMesh>& parts) {
  return merged(parts).V;
}

// The rotation taking direction a onto direction b (shortest arc).
Eigen::Matrix3d aligning(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return Eigen::Quaterniond::FromTwoVectors(a, b).toRotationMatrix();
}

Eigen::Vector3d sphere_centre(const std::filesystem::path& file) {
  const mesh::IndexedMesh surface = mesh::read_mesh(file);
  return fit::sphere_fit(surface.V).center;
}

// A marker_on_bone landmark farther than this from its marker is reported.
constexpr double kFarFromMarkerMm = 100.0;

// Everything the build needs at hand.
class Builder {
 public:
  Builder(const AtlasRecipe& recipe, const AtlasBuildOptions& options)
      : recipe_(recipe), options_(options) {}

  AtlasBuildReport run(const std::filesystem::path& out_dir);

 private:
  void read_model();
  void read_atlas_frame_bones();
  void register_bodies();
  RegistrationResult register_body(const RecipeRegistration& reg);
  RegistrationResult register_through_joint(const RecipeRegistration& reg,
                                            const Eigen::MatrixX3d& source,
                                            const mesh::IndexedMesh& target) const;
  std::vector<mesh::IndexedMesh> opensim_meshes(const std::string& body,
                                                const std::vector<std::string>& files) const;
  void build_bones();
  void build_joints();
  void build_muscles();
  void map_markers();
  void place_landmarks();
  void clean_and_attach();
  void write(const std::filesystem::path& out_dir);

  const AtlasRecipe& recipe_;
  const AtlasBuildOptions& options_;
  AtlasBuildReport report_;
  opensim::OsimModel model_;
  BodyMaps maps_;
  double midline_x_ = 0.0;
  std::map<std::string, mesh::IndexedMesh> bone_meshes_;       // full resolution, atlas (mm)
  std::map<std::string, mesh::IndexedMesh> muscle_meshes_;     // full resolution, atlas (mm)
  std::map<std::string, mesh::IndexedMesh> structure_meshes_;  // full resolution, atlas (mm)
  std::map<std::string, Eigen::Vector3d> marker_positions_;    // atlas (mm)
  Atlas atlas_;
};

void Builder::read_model() {
  model_ = opensim::read_osim(data_file(options_, recipe_.opensim.model, "opensim.model"));
  for (const auto& [body, pose] : opensim::body_poses(model_)) maps_.pose[body] = pose;
  for (const RecipeBone& bone : recipe_.bones) {
    if (!maps_.pose.contains(bone.body)) {
      throw InvalidInputError("recipe " + recipe_.source.string() + ": bone " + bone.name +
                              ": the OpenSim model has no body '" + bone.body + "'");
    }
    // The bone named like its body stands for it; otherwise the first listed.
    if (bone.name == bone.body || !maps_.primary_bone.contains(bone.body)) {
      maps_.primary_bone[bone.body] = bone.name;
    }
  }
}

void Builder::read_atlas_frame_bones() {
  // The midline bone first (it is never mirrored: it defines the plane).
  for (const RecipeBone& bone : recipe_.bones) {
    if (bone.file.empty()) continue;
    if (bone.name == recipe_.midline_bone && bone.mirror) {
      throw InvalidInputError("recipe: the midline bone " + bone.name + " cannot be mirrored");
    }
    bone_meshes_[bone.name] =
        mesh::read_mesh(data_file(options_, bone.file, "bones." + bone.name + ".file"));
  }
  if (!bone_meshes_.contains(recipe_.midline_bone)) {
    throw InvalidInputError("recipe: the midline bone " + recipe_.midline_bone +
                            " must be given as a surface file");
  }
  midline_x_ = mesh::mass_properties(bone_meshes_.at(recipe_.midline_bone)).centroid.x();
  report_.notes.push_back("midline (sagittal plane) at x = " + std::to_string(midline_x_) +
                          " mm, the centroid of " + recipe_.midline_bone);
  for (const RecipeBone& bone : recipe_.bones) {
    if (!bone.file.empty() && bone.mirror) {
      bone_meshes_[bone.name] = mirrored(bone_meshes_[bone.name], midline_x_);
    }
  }
}

std::vector<mesh::IndexedMesh> Builder::opensim_meshes(
    const std::string& body, const std::vector<std::string>& files) const {
  const opensim::Body* source = model_.find_body(body);
  std::vector<mesh::IndexedMesh> parts;
  for (const std::string& file : files) {
    Eigen::Vector3d scale_factors = Eigen::Vector3d::Ones();
    if (source != nullptr) {
      for (const opensim::AttachedMesh& attached : source->geometry) {
        if (attached.mesh_file == file) scale_factors = attached.scale_factors;
      }
    }
    mesh::IndexedMesh part = mesh::read_mesh(
        data_file(options_, recipe_.opensim.geometry + "/" + file, "opensim mesh of " + body));
    Eigen::Affine3d to_ground = Eigen::Affine3d::Identity();
    to_ground = maps_.pose.at(body) * Eigen::Scaling(scale_factors);
    parts.push_back(transformed(part, to_ground));  // ground, m
  }
  return parts;
}

RegistrationResult Builder::register_body(const RecipeRegistration& reg) {
  const Eigen::Matrix3d axes = ground_axes_in_atlas();
  RegistrationOptions options;
  options.anisotropic = reg.anisotropic;
  const auto joint_origin = [&](const std::string& joint_name, bool parent_side) {
    const opensim::Joint* joint = model_.find_joint(joint_name);
    if (joint == nullptr) {
      throw InvalidInputError("registration of " + reg.body + ": the OpenSim model has no joint " +
                              joint_name);
    }
    const opensim::FrameRef& frame = parent_side ? joint->parent : joint->child;
    return Eigen::Vector3d(
        (maps_.pose.at(frame.body) * opensim::frame_in_body(frame)).translation());
  };
  const Eigen::MatrixX3d source = vertices_of(opensim_meshes(reg.body, reg.meshes));

  if (reg.method == "hip_and_sacrum") {
    const Eigen::Vector3d centre_r =
        sphere_centre(data_file(options_, reg.acetabulum, "registration." + reg.body));
    Eigen::Vector3d centre_l = centre_r;
    centre_l.x() = 2.0 * midline_x_ - centre_r.x();
    const Eigen::Vector3d hip_r = joint_origin("hip_r", true);
    const Eigen::Vector3d hip_l = joint_origin("hip_l", true);
    const double scale = (centre_r - centre_l).norm() / (hip_r - hip_l).norm();
    Eigen::Affine3d start = Eigen::Affine3d::Identity();
    start.linear() = scale * axes;
    start.translation() = 0.5 * (centre_r + centre_l) - start.linear() * (0.5 * (hip_r + hip_l));
    const mesh::AabbTree target(bone_meshes_.at(reg.sacrum));
    // Each hip centre counts as much as the whole sacrum surface.
    return register_points(
        source, &target,
        {{"hip_centre_r", hip_r, centre_r, 1.0}, {"hip_centre_l (mirrored)", hip_l, centre_l, 1.0}},
        start, options);
  }
  if (reg.method == "head_and_condyles") {
    const Eigen::Vector3d head =
        sphere_centre(data_file(options_, reg.head, "registration." + reg.body + ".head"));
    const mesh::IndexedMesh condyles =
        mesh::read_mesh(data_file(options_, reg.condyles, "registration." + reg.body));
    const Eigen::Vector3d knee_target = mesh::mass_properties(condyles).centroid;
    const Eigen::Vector3d hip = joint_origin("hip_r", false);
    // gait2392 carries the femur length in the knee's translation functions: the
    // knee centre is the origin of the joint's child frame (on the tibia).
    const Eigen::Vector3d knee = joint_origin("knee_r", false);
    const Eigen::Vector3d model_axis = axes * (knee - hip);
    const Eigen::Vector3d subject_axis = knee_target - head;
    Eigen::Affine3d start = Eigen::Affine3d::Identity();
    start.linear() =
        (subject_axis.norm() / model_axis.norm()) * aligning(model_axis, subject_axis) * axes;
    start.translation() = head - start.linear() * hip;
    // Only the distal femur is fitted to the distal cartilage: the vertices
    // of the last fifth of the head-knee axis.
    std::vector<Eigen::Vector3d> distal;
    for (Eigen::Index i = 0; i < source.rows(); ++i) {
      const Eigen::Vector3d p = source.row(i).transpose();
      if ((p - hip).dot(knee - hip) / (knee - hip).squaredNorm() > 0.8) distal.push_back(p);
    }
    Eigen::MatrixX3d distal_rows(static_cast<Eigen::Index>(distal.size()), 3);
    for (std::size_t i = 0; i < distal.size(); ++i) {
      distal_rows.row(static_cast<Eigen::Index>(i)) = distal[i].transpose();
    }
    const mesh::AabbTree target(condyles);
    return register_points(distal_rows, &target, {{"femoral_head_centre", hip, head, 1.0}}, start,
                           options);
  }
  std::vector<mesh::IndexedMesh> targets;
  for (const std::string& target : reg.targets) targets.push_back(bone_meshes_.at(target));
  const mesh::IndexedMesh target_mesh = merged(targets);
  if (reg.method == "joint") return register_through_joint(reg, source, target_mesh);
  // surface: the model's bone onto the subject's, started from the volume
  // ratio and the centroids.
  const mesh::IndexedMesh model_mesh = merged(opensim_meshes(reg.body, reg.meshes));
  const mesh::MassProperties model_props = mesh::mass_properties(model_mesh);
  const mesh::MassProperties target_props = mesh::mass_properties(target_mesh);
  const double scale = std::cbrt(std::abs(target_props.volume / model_props.volume));
  Eigen::Affine3d start = Eigen::Affine3d::Identity();
  start.linear() = scale * axes;
  start.translation() = target_props.centroid - start.linear() * model_props.centroid;
  options.keep_scale = true;
  std::vector<RegistrationAnchor> anchors;
  if (!reg.joint_anchor.empty()) {
    const opensim::Joint* joint = model_.find_joint(reg.joint_anchor);
    if (joint == nullptr || joint->child.body != reg.body || !maps_.has(joint->parent.body)) {
      throw InvalidInputError("joint_anchor " + reg.joint_anchor +
                              " must be a joint whose child "
                              "is " +
                              reg.body + " and whose parent is registered before it");
    }
    // The joint centre as the parent places it (the child frame's origin at
    // the default pose, i.e. with the joint's own translations applied).
    const Eigen::Vector3d centre = joint_origin(reg.joint_anchor, false);
    anchors.push_back(
        {reg.joint_anchor + " centre", centre, maps_.map.at(joint->parent.body) * centre, 1.0});
  }
  const mesh::AabbTree target(target_mesh);
  return register_points(source, &target, anchors, start, options);
}

// The child's map is the parent's map after the joint's motion: a point of
// the child at the default pose goes to where the joint at q carries it,
// then through the parent's map. The one coordinate q is the value whose
// placement of the model's bone is nearest the subject's (mean of the
// closest 80% of vertex distances): a 1-degree scan over the coordinate's
// range, then golden-section refinement.
RegistrationResult Builder::register_through_joint(const RecipeRegistration& reg,
                                                   const Eigen::MatrixX3d& source,
                                                   const mesh::IndexedMesh& target) const {
  const opensim::Joint* joint = model_.find_joint(reg.joint);
  if (joint == nullptr || joint->child.body != reg.body || !maps_.has(joint->parent.body) ||
      joint->coordinates.size() != 1) {
    throw InvalidInputError("joint " + reg.joint +
                            " must be a one-coordinate joint whose child is " + reg.body +
                            " and whose parent is registered before it");
  }
  const opensim::Coordinate& coordinate = joint->coordinates.front();
  const Eigen::Affine3d& parent_map = maps_.map.at(joint->parent.body);
  const Eigen::Isometry3d parent_frame =
      maps_.pose.at(joint->parent.body) * opensim::frame_in_body(joint->parent);
  const Eigen::Isometry3d child_frame = opensim::frame_in_body(joint->child);
  const Eigen::Isometry3d child_pose = maps_.pose.at(reg.body);
  const auto map_at = [&](double q) {
    const Eigen::Isometry3d moved = parent_frame *
                                    opensim::joint_motion(*joint, {{coordinate.name, q}}) *
                                    child_frame.inverse() * child_pose.inverse();
    return Eigen::Affine3d(parent_map * moved);
  };
  const mesh::AabbTree tree(target);
  std::vector<double> distances(static_cast<std::size_t>(source.rows()));
  const auto fit = [&](double q) {
    const Eigen::Affine3d map = map_at(q);
    for (Eigen::Index i = 0; i < source.rows(); ++i) {
      distances[static_cast<std::size_t>(i)] = std::sqrt(
          tree.closest_point(map * Eigen::Vector3d(source.row(i).transpose())).squared_distance);
    }
    std::ranges::sort(distances);
    const std::size_t kept = std::max<std::size_t>(1, distances.size() * 4 / 5);
    double sum = 0.0;
    for (std::size_t i = 0; i < kept; ++i) sum += distances[i];
    return sum / static_cast<double>(kept);
  };
  constexpr double kStep = 3.14159265358979 / 180.0;
  double best_q = coordinate.default_value;
  double best = fit(best_q);
  for (double q = coordinate.range[0]; q <= coordinate.range[1]; q += kStep) {
    if (const double score = fit(q); score < best) {
      best = score;
      best_q = q;
    }
  }
  double low = best_q - kStep;
  double high = best_q + kStep;
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 40; ++i) {
    const double a = high - ratio * (high - low);
    const double b = low + ratio * (high - low);
    if (fit(a) < fit(b)) {
      high = b;
    } else {
      low = a;
    }
  }
  best_q = 0.5 * (low + high);
  RegistrationResult result;
  result.map = map_at(best_q);
  result.scale = std::cbrt(std::abs(result.map.linear().determinant()));
  result.mean_distance_mm = fit(best_q);
  double squares = 0.0;
  for (const double d : distances) squares += d * d;
  result.rms_mm = std::sqrt(squares / static_cast<double>(distances.size()));
  result.pairs = static_cast<int>(distances.size());
  return result;
}

void Builder::register_bodies() {
  // Direct methods first, then bodies following others (in recipe order,
  // repeated until every follower is resolved).
  for (const RecipeRegistration& reg : recipe_.registrations) {
    if (reg.method == "follow") continue;
    RegistrationResult result;
    try {
      result = register_body(reg);
    } catch (const InvalidInputError& error) {
      throw InvalidInputError("registration." + reg.body + " (" + reg.method +
                              "): " + error.what());
    }
    maps_.map[reg.body] = result.map;
    report_.registrations.push_back({reg.body, reg.method, result.scale / 1000.0, result.rms_mm,
                                     result.mean_distance_mm, result.pairs,
                                     result.anchor_residuals_mm});
  }
  bool progress = true;
  while (progress) {
    progress = false;
    for (const RecipeRegistration& reg : recipe_.registrations) {
      if (reg.method != "follow" || maps_.has(reg.body) || !maps_.has(reg.follow)) continue;
      maps_.map[reg.body] = maps_.map.at(reg.follow);
      report_.registrations.push_back(
          {reg.body, "follow " + reg.follow, maps_.scale(reg.body) / 1000.0, 0.0, 0.0, 0, {}});
      progress = true;
    }
  }
  for (const RecipeRegistration& reg : recipe_.registrations) {
    if (!maps_.has(reg.body)) {
      throw InvalidInputError("registration." + reg.body + ": follows '" + reg.follow +
                              "', which is never registered (or the chain is a cycle)");
    }
  }
}

void Builder::build_bones() {
  for (const RecipeBone& recipe_bone : recipe_.bones) {
    if (!recipe_bone.opensim_meshes.empty()) {
      mesh::IndexedMesh surface =
          transformed(merged(opensim_meshes(recipe_bone.body, recipe_bone.opensim_meshes)),
                      maps_.map.at(recipe_bone.body));
      const mesh::MeshCheckReport health = mesh::check_mesh(surface);
      if (!health.single_solid()) {
        // Holes, non-manifold edges or several pieces (gait2392's pelvis):
        // the boundary of the solid it encloses instead.
        surface = mesh::solidify(surface, {2.0, 2});
        report_.notes.push_back(recipe_bone.name +
                                ": OpenSim mesh not a single closed 2-manifold; rebuilt as the "
                                "boundary of the solid it encloses (2 mm grid)");
      }
      if (recipe_bone.remesh_edge_mm > 0) {
        surface = mesh::remesh_uniform(surface, {recipe_bone.remesh_edge_mm, 5});
      }
      if (recipe_bone.mirror) surface = mirrored(surface, midline_x_);
      bone_meshes_[recipe_bone.name] = std::move(surface);
    }
    Bone bone;
    bone.name = recipe_bone.name;
    bone.tags = recipe_bone.tags;
    bone.frame = maps_.frame(recipe_bone.body, maps_.pose.at(recipe_bone.body));
    atlas_.bones.push_back(std::move(bone));
  }
}

void Builder::build_joints() {
  std::set<std::string> registered;
  for (const auto& [body, map] : maps_.map) registered.insert(body);
  for (const opensim::Joint& source : model_.joints) {
    if (!registered.contains(source.parent.body) || !registered.contains(source.child.body)) {
      continue;
    }
    MappedJoint mapped = map_joint(source, maps_);
    JointBuildReport joint_report{mapped.joint.name, {}, mapped.mismatch_mm, mapped.mismatch_deg};
    for (const Coordinate& coordinate : mapped.joint.coordinates) {
      joint_report.rest_values.emplace_back(coordinate.name, coordinate.rest_value);
    }
    report_.joints.push_back(std::move(joint_report));
    atlas_.find_bone(mapped.joint.child)->parent_joint = mapped.joint.name;
    atlas_.joints.push_back(std::move(mapped.joint));
  }
  // Further bones of a body are welded to the bone standing for it.
  for (const RecipeBone& recipe_bone : recipe_.bones) {
    const std::string& primary = maps_.primary_bone.at(recipe_bone.body);
    if (primary == recipe_bone.name) continue;
    Joint weld;
    weld.name = recipe_bone.name + "_weld";
    weld.type = JointType::kWeld;
    weld.parent = primary;
    weld.child = recipe_bone.name;
    weld.parent_frame = atlas_.find_bone(recipe_bone.name)->frame;
    weld.child_frame = weld.parent_frame;
    atlas_.find_bone(recipe_bone.name)->parent_joint = weld.name;
    atlas_.joints.push_back(std::move(weld));
  }
}

void Builder::build_muscles() {
  std::map<std::string, double> rest;
  for (const Joint& joint : atlas_.joints) {
    for (const Coordinate& coordinate : joint.coordinates) {
      rest[coordinate.name] = coordinate.kind == CoordinateKind::kTranslational
                                  ? coordinate.rest_value / 1000.0
                                  : coordinate.rest_value;
    }
  }
  for (const RecipeMuscle& recipe_muscle : recipe_.muscles) {
    mesh::IndexedMesh surface = mesh::read_mesh(
        data_file(options_, recipe_muscle.file, "muscles." + recipe_muscle.name + ".file"));
    if (recipe_muscle.mirror) surface = mirrored(surface, midline_x_);
    muscle_meshes_[recipe_muscle.name] = std::move(surface);
    Muscle muscle;
    muscle.name = recipe_muscle.name;
    muscle.tags = recipe_muscle.tags;
    muscle.architecture = recipe_muscle.architecture;
    double fibre_length = 0.0;
    double slack_length = 0.0;
    double pennation = 0.0;
    for (const std::string& line_name : recipe_muscle.action_lines) {
      const opensim::Muscle* source = model_.find_muscle(line_name);
      if (source == nullptr) {
        throw InvalidInputError("recipe: muscle " + recipe_muscle.name +
                                ": the OpenSim model has "
                                "no muscle '" +
                                line_name + "'");
      }
      muscle.action_lines.push_back(
          map_action_line(model_, *source, maps_, rest, muscle.wrap_obstacles, report_.notes));
      muscle.max_isometric_force_n += source->max_isometric_force;
      // Lengths of the model scale with the bones the path spans (mm per m).
      const double scale = 0.5 * (maps_.scale(source->path_points.front().frame.body) +
                                  maps_.scale(source->path_points.back().frame.body));
      fibre_length += scale * source->optimal_fiber_length;
      slack_length += scale * source->tendon_slack_length;
      pennation += source->pennation_angle_at_optimal;
    }
    if (!recipe_muscle.surface_line.empty()) {
      const std::string& origin = recipe_muscle.surface_line[0];
      const std::string& insertion = recipe_muscle.surface_line[1];
      const mesh::AabbTree origin_tree(bone_meshes_.at(origin));
      const mesh::AabbTree insertion_tree(bone_meshes_.at(insertion));
      SurfaceLine line = surface_action_line(
          recipe_muscle.name, muscle_meshes_.at(recipe_muscle.name), {origin, &origin_tree},
          {insertion, &insertion_tree}, recipe_.attachment_distance_mm);
      muscle.action_lines.push_back(std::move(line.line));
      // Lengths from the geometry: the belly along the line is the fibre
      // length, the rest of the line the tendon.
      muscle.optimal_fibre_length_mm = line.belly_mm;
      muscle.tendon_slack_length_mm = line.tendon_mm;
      std::string note = recipe_muscle.name;
      note.append(": no OpenSim path; its action line runs between its contacts with ")
          .append(origin)
          .append(" and ")
          .append(insertion)
          .append(" (fibre and tendon lengths from its surface; no force)");
      report_.notes.push_back(std::move(note));
    }
    if (const auto lines = static_cast<double>(recipe_muscle.action_lines.size());
        lines > 0 && recipe_muscle.surface_line.empty()) {
      muscle.optimal_fibre_length_mm = fibre_length / lines;
      muscle.tendon_slack_length_mm = slack_length / lines;
      muscle.pennation_angle_rad = pennation / lines;
    }
    atlas_.muscles.push_back(std::move(muscle));
  }
}

void Builder::map_markers() {
  std::vector<opensim::MarkerDefinition> markers;
  if (!recipe_.opensim.marker_set.empty()) {
    markers = opensim::read_marker_set(
        data_file(options_, recipe_.opensim.marker_set, "opensim.marker_set"));
  } else {
    for (const opensim::Marker& marker : model_.markers) {
      markers.push_back({marker.name, marker.frame.body,
                         opensim::frame_in_body(marker.frame) * marker.location, marker.fixed});
    }
  }
  int skipped = 0;
  for (const opensim::MarkerDefinition& definition : markers) {
    if (!maps_.has(definition.body)) {
      ++skipped;
      continue;
    }
    Marker marker;
    marker.name = definition.name;
    marker.bone = maps_.primary_bone.at(definition.body);
    marker.position = maps_.point(definition.body, definition.location);
    marker.fixed = definition.fixed;
    marker_positions_[marker.name] = marker.position;
    atlas_.markers.push_back(std::move(marker));
  }
  if (skipped > 0) {
    report_.notes.push_back(std::to_string(skipped) +
                            " marker(s) on bodies outside the atlas (left leg, torso) left out");
  }
}

void Builder::place_landmarks() {
  for (const RecipeLandmark& recipe_landmark : recipe_.landmarks) {
    Landmark landmark;
    landmark.name = recipe_landmark.name;
    landmark.bone = recipe_landmark.bone;
    landmark.tags = recipe_landmark.tags;
    landmark.description = recipe_landmark.description;
    const std::string field = "landmarks." + recipe_landmark.name;
    if (recipe_landmark.method == "sphere_centre") {
      landmark.position = sphere_centre(data_file(options_, recipe_landmark.file, field));
    } else if (recipe_landmark.method == "centroid") {
      landmark.position = mesh::mass_properties(bone_meshes_.at(recipe_landmark.bone)).centroid;
    } else if (recipe_landmark.method == "joint_centre") {
      const Joint* joint = atlas_.find_joint(recipe_landmark.joint);
      if (joint == nullptr) {
        throw InvalidInputError("recipe: " + field + ": no joint '" + recipe_landmark.joint +
                                "' in the atlas");
      }
      landmark.position = joint->child_frame.translation();
    } else {  // marker_on_bone
      const auto it = marker_positions_.find(recipe_landmark.marker);
      if (it == marker_positions_.end()) {
        throw InvalidInputError("recipe: " + field + ": no marker '" + recipe_landmark.marker +
                                "' on an atlas bone");
      }
      const BonePoint on_bone =
          closest_on_segment(atlas_, bone_meshes_, recipe_landmark.bone, it->second);
      landmark.bone = on_bone.bone;
      landmark.position = on_bone.position;
      if (on_bone.distance_mm > kFarFromMarkerMm) {
        report_.notes.push_back("landmark " + landmark.name + " lies " +
                                std::to_string(on_bone.distance_mm) + " mm from marker " +
                                recipe_landmark.marker + ", farther than skin sits from bone: " +
                                "is bone " + recipe_landmark.bone + " the one under the marker?");
      }
    }
    atlas_.landmarks.push_back(std::move(landmark));
  }
}

void Builder::clean_and_attach() {
  // One signed distance per bone; its tree serves the closest-point queries.
  std::map<std::string, std::unique_ptr<mesh::SignedDistance>> distances;
  std::map<std::string, const mesh::AabbTree*> trees;
  // Split points of the action lines may ride on any bone their segment
  // passes along the chain (the femur for a hamstring's pelvis-tibia span).
  ActionLineFitOptions fit_options;
  for (const Joint& joint : atlas_.joints) {
    fit_options.parent_bone[joint.child] = joint.parent;
    fit_options.joint_centre[joint.child] = joint.child_frame.translation();
  }
  for (const auto& [name, surface] : bone_meshes_) {
    if (surface.F.rows() == 0) {
      throw InvalidInputError("atlas build: bone " + name + " has an empty surface");
    }
    distances[name] = std::make_unique<mesh::SignedDistance>(surface);
    trees[name] = &distances[name]->tree();
  }
  // Bone points under the cartilages the recipe keeps clear take no muscle ends.
  std::vector<std::pair<std::unique_ptr<mesh::SignedDistance>, double>> cartilages;
  for (const RecipeStructure& structure : recipe_.structures) {
    if (structure.muscle_ends_clear_mm > 0) {
      cartilages.emplace_back(
          std::make_unique<mesh::SignedDistance>(structure_meshes_.at(structure.name)),
          structure.muscle_ends_clear_mm);
    }
  }
  if (!cartilages.empty()) {
    fit_options.articular = [&cartilages](const Eigen::Vector3d& p) {
      return std::ranges::any_of(cartilages, [&](const auto& cartilage) {
        return cartilage.first->at(p) < cartilage.second;
      });
    };
  }
  MuscleCleanupOptions cleanup;
  cleanup.tolerance_mm = recipe_.penetration_tolerance_mm;
  AttachmentOptions attachment;
  attachment.contact_distance_mm = recipe_.attachment_distance_mm;
  attachment.radius_mm = recipe_.attachment_radius_mm;
  // Each muscle on the machine's threads (nothing shared is written), its
  // report entries gathered and appended in muscle order.
  struct MuscleEntries {
    MuscleBuildReport muscle;
    std::vector<ActionLineBuildReport> lines;
    std::vector<std::string> notes;
  };
  std::vector<MuscleEntries> entries(atlas_.muscles.size());
  const auto clean_and_attach_muscle = [&](std::size_t index) {
    Muscle& muscle = atlas_.muscles[index];
    MuscleEntries& out = entries[index];
    mesh::IndexedMesh& surface = muscle_meshes_.at(muscle.name);
    Eigen::AlignedBox3d box = mesh::bounding_box(surface);
    box.min().array() -= 1.0;
    box.max().array() += 1.0;
    std::vector<const mesh::SignedDistance*> nearby;
    for (const auto& [name, distance] : distances) {
      if (distance->tree().bounds().intersects(box)) nearby.push_back(distance.get());
    }
    const MuscleCleanupReport cleaned = push_muscle_out_of_bones(surface, nearby, cleanup);
    MuscleBuildReport muscle_report;
    muscle_report.name = muscle.name;
    muscle_report.faces = static_cast<int>(surface.F.rows());
    muscle_report.volume_mm3 = cleaned.volume_after_mm3;
    muscle_report.max_penetration_before_mm = cleaned.max_depth_before_mm;
    muscle_report.vertices_moved = cleaned.vertices_moved;
    muscle_report.volume_change_percent =
        100.0 * (cleaned.volume_after_mm3 - cleaned.volume_before_mm3) / cleaned.volume_before_mm3;
    out.muscle = muscle_report;

    const mesh::AabbTree muscle_tree(surface);
    const mesh::WindingNumber winding(muscle_tree);
    // A line drawn from the muscle's own surface has no model place to keep.
    ActionLineFitOptions muscle_fit = fit_options;
    const auto from_recipe = std::ranges::find_if(
        recipe_.muscles, [&](const RecipeMuscle& m) { return m.name == muscle.name; });
    if (from_recipe != recipe_.muscles.end() && !from_recipe->surface_line.empty()) {
      muscle_fit.max_via_shift_mm = std::numeric_limits<double>::infinity();
    }
    for (const ActionLineFitReport& fitted : fit_action_lines(
             muscle, muscle_tree, [&](const Eigen::Vector3d& q) { return winding.is_inside(q); },
             trees, muscle_fit)) {
      out.lines.push_back({muscle.name, fitted.line, fitted.inside_before, fitted.inside_after,
                           fitted.points_added, fitted.origin_on_contact,
                           fitted.insertion_on_contact});
    }
    const auto add_area = [&](std::vector<AttachmentArea>& areas, const PathPoint& end,
                              const std::string& which) {
      bool fell_back = false;
      const AttachmentArea area = find_attachment_area(end.bone, *trees.at(end.bone), muscle_tree,
                                                       end.position, attachment, &fell_back);
      if (fell_back) {
        out.notes.push_back(muscle.name + ": no muscle-bone contact near its " + which + " on " +
                            end.bone +
                            "; the area is the bone patch nearest the "
                            "action line's end");
      }
      const auto same_bone = std::ranges::find_if(
          areas, [&](const AttachmentArea& other) { return other.bone == area.bone; });
      if (same_bone == areas.end()) {
        areas.push_back(area);
      } else {
        *same_bone = merge_attachment_areas(*same_bone, area, bone_meshes_.at(area.bone));
      }
    };
    for (const ActionLine& line : muscle.action_lines) {
      if (line.points.size() < 2) continue;
      add_area(muscle.origins, line.points.front(), "origin");
      add_area(muscle.insertions, line.points.back(), "insertion");
    }
  };
  parallel_for(atlas_.muscles.size(), machine_threads(), clean_and_attach_muscle);
  for (MuscleEntries& entry : entries) {
    report_.muscles.push_back(std::move(entry.muscle));
    for (ActionLineBuildReport& line : entry.lines) report_.action_lines.push_back(std::move(line));
    for (std::string& note : entry.notes) report_.notes.push_back(std::move(note));
  }
}

std::vector<MeshLevel> write_levels(const std::filesystem::path& dir, const std::string& name,
                                    const mesh::IndexedMesh& full, const std::vector<int>& lods) {
  std::vector<MeshLevel> levels;
  const std::string folder = "meshes/" + name;
  std::filesystem::create_directories(dir / folder);
  const auto put = [&](const std::string& level, const mesh::IndexedMesh& surface) {
    const std::string file = folder + "/" + level + ".ply";
    mesh::write_mesh(surface, dir / file);
    levels.push_back({level, file, static_cast<int>(surface.F.rows())});
  };
  put("full", full);
  // Each level from the one before (quicker than from the full mesh each time).
  mesh::IndexedMesh coarse = full;
  for (std::size_t i = 0; i < lods.size(); ++i) {
    mesh::DecimateOptions decimation;
    decimation.target_faces = lods[i];
    // A coarse source already below the target is kept as it is.
    if (coarse.F.rows() > lods[i]) coarse = mesh::decimate(coarse, decimation);
    put("lod" + std::to_string(i + 1), coarse);
  }
  return levels;
}

void Builder::write(const std::filesystem::path& out_dir) {
  // Every element's levels (simplified and written) on the machine's
  // threads: each writes its own files, so the order does not matter.
  struct Job {
    const std::string* name;
    const mesh::IndexedMesh* surface;
    std::vector<MeshLevel>* levels;
  };
  std::vector<Job> jobs;
  for (Bone& bone : atlas_.bones)
    jobs.push_back({&bone.name, &bone_meshes_.at(bone.name), &bone.meshes});
  for (Muscle& muscle : atlas_.muscles) {
    jobs.push_back({&muscle.name, &muscle_meshes_.at(muscle.name), &muscle.meshes});
  }
  for (Structure& structure : atlas_.structures) {
    jobs.push_back({&structure.name, &structure_meshes_.at(structure.name), &structure.meshes});
  }
  // Largest first, so the last one to start is a small one.
  std::ranges::sort(
      jobs, [](const Job& a, const Job& b) { return a.surface->F.rows() > b.surface->F.rows(); });
  parallel_for(jobs.size(), machine_threads(), [&](std::size_t i) {
    *jobs[i].levels = write_levels(out_dir, *jobs[i].name, *jobs[i].surface, recipe_.lod_faces);
  });
  write_atlas_manifest(atlas_, out_dir);
}

AtlasBuildReport Builder::run(const std::filesystem::path& out_dir) {
  const auto started = std::chrono::steady_clock::now();
  atlas_.name = recipe_.name;
  atlas_.description = recipe_.description;
  atlas_.frame_description = recipe_.frame_description;
  atlas_.provenance.push_back("recipe " + recipe_.source.filename().string());
  atlas_.provenance.push_back("OpenSim model " + recipe_.opensim.model);
  for (const RecipeBone& bone : recipe_.bones) {
    atlas_.provenance.push_back("bone " + bone.name + ": " +
                                (bone.file.empty()
                                     ? "OpenSim " + recipe_.opensim.geometry + " registered"
                                     : bone.file + (bone.mirror ? " (mirrored)" : "")));
  }
  for (const RecipeMuscle& muscle : recipe_.muscles) {
    atlas_.provenance.push_back("muscle " + muscle.name + ": " + muscle.file +
                                (muscle.mirror ? " (mirrored)" : ""));
  }
  for (const RecipeStructure& structure : recipe_.structures) {
    atlas_.provenance.push_back(std::string(structure_kind_name(structure.kind)) + " " +
                                structure.name + ": " + structure.file);
  }
  read_model();
  read_atlas_frame_bones();
  register_bodies();
  build_bones();
  build_joints();
  build_muscles();
  map_markers();
  place_landmarks();
  for (const RecipeRegion& recipe_region : recipe_.regions) {
    Region region{recipe_region.name, recipe_region.tags, {}, {}, {}};
    for (const RecipeBone& bone : recipe_.bones) {
      if (bone.region == region.name) region.bones.push_back(bone.name);
    }
    for (const RecipeMuscle& muscle : recipe_.muscles) {
      if (muscle.region == region.name) region.muscles.push_back(muscle.name);
    }
    atlas_.regions.push_back(std::move(region));
  }
  report_.structures = add_structures(
      recipe_,
      [&](const std::string& file, const std::string& field) {
        return mesh::read_mesh(data_file(options_, file, field));
      },
      bone_meshes_, {}, atlas_, structure_meshes_);
  clean_and_attach();
  report_.wrap_surfaces = add_wrap_surfaces(recipe_, bone_meshes_, atlas_);

  // Written beside the target, then swapped in: a failed build never leaves
  // half an atlas where a complete one was.
  const std::filesystem::path partial = out_dir.string() + ".partial";
  std::filesystem::remove_all(partial);
  std::filesystem::create_directories(partial);
  write(partial);
  replace_directory(partial, out_dir);
  // One note per fact (a muscle with three action lines meets the same bone
  // three times).
  std::vector<std::string> notes;
  std::set<std::string> seen;
  for (std::string& note : report_.notes) {
    if (seen.insert(note).second) notes.push_back(std::move(note));
  }
  report_.notes = std::move(notes);
  report_.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report_;
}

}  // namespace

BonePoint closest_on_segment(const Atlas& atlas,
                             const std::map<std::string, mesh::IndexedMesh>& surfaces,
                             std::string_view bone, const Eigen::Vector3d& point) {
  std::optional<BonePoint> nearest;
  for (const std::string& candidate : welded_together(atlas, bone)) {
    const auto surface = surfaces.find(candidate);
    if (surface == surfaces.end() || surface->second.F.rows() == 0) continue;
    const mesh::AabbTree tree(surface->second);
    const Eigen::Vector3d on_surface = tree.closest_point(point).point;
    const double distance = (on_surface - point).norm();
    if (!nearest || distance < nearest->distance_mm) {
      nearest = BonePoint{candidate, on_surface, distance};
    }
  }
  if (!nearest) {
    throw InvalidInputError("no surface for bone '" + std::string(bone) +
                            "' or the bones welded to it");
  }
  return *nearest;
}

AtlasBuildReport build_atlas(const AtlasRecipe& recipe, const AtlasBuildOptions& options,
                             const std::filesystem::path& out_dir) {
  Builder builder(recipe, options);
  return builder.run(out_dir);
}

}  // namespace mmm::atlas

#include "core/scaling/atlas_scaling.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <sstream>

#include "core/atlas/bone_registration.h"
#include "core/atlas/kinematic_chain.h"
#include "core/atlas/structure_carriage.h"
#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/parallel_for.h"

namespace mmm::scaling {
namespace {

using Eigen::Affine3d;
using Eigen::Vector3d;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

const mesh::IndexedMesh& full_mesh(const atlas::AtlasMeshes& meshes, const std::string& element) {
  const auto found = meshes.find(element);
  if (found == meshes.end() || !found->second.contains("full")) {
    throw InvalidInputError("atlas scaling: no full-resolution mesh for '" + element + "'");
  }
  return found->second.at("full");
}

const mesh::IndexedMesh& coarsest_mesh(const atlas::AtlasMeshes& meshes, const atlas::Bone& bone) {
  return meshes.at(bone.name).at(bone.meshes.back().level);
}

using atlas::chain_order;
using atlas::joint_to;
using atlas::moving_with;

Eigen::MatrixX3d reconstruct_all(const std::vector<AffineAnchor>& anchors,
                                 const Eigen::MatrixX3d& vertices) {
  Eigen::MatrixX3d out(static_cast<Eigen::Index>(anchors.size()), 3);
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    out.row(static_cast<Eigen::Index>(i)) = reconstruct(anchors[i], vertices).transpose();
  }
  return out;
}

double face_area_sum(const mesh::IndexedMesh& surface, const std::vector<int>& faces) {
  double area = 0.0;
  for (const int f : faces) {
    if (f < 0 || f >= surface.F.rows()) continue;
    const Vector3d a = surface.V.row(surface.F(f, 0)).transpose();
    const Vector3d b = surface.V.row(surface.F(f, 1)).transpose();
    const Vector3d c = surface.V.row(surface.F(f, 2)).transpose();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

}  // namespace

std::shared_ptr<const PreparedAtlas> prepare_atlas(atlas::Atlas atlas, atlas::AtlasMeshes meshes,
                                                   const AtlasScalingOptions& options) {
  const Clock::time_point start = Clock::now();
  auto prepared = std::make_shared<PreparedAtlas>();
  prepared->atlas = std::move(atlas);
  prepared->meshes = std::move(meshes);
  const atlas::Atlas& a = prepared->atlas;
  std::vector<std::string> elements;
  for (const atlas::Bone& bone : a.bones) {
    prepared->bone_names.push_back(bone.name);
    elements.push_back(bone.name);
  }
  for (const atlas::Muscle& muscle : a.muscles) elements.push_back(muscle.name);
  for (const atlas::Structure& structure : a.structures) elements.push_back(structure.name);
  for (const std::string& element : elements) {
    mesh::validate_indices_and_coordinates(full_mesh(prepared->meshes, element));
    prepared->anchors[element] = nullptr;
    prepared->level_anchors[element];
  }
  for (const atlas::Bone& bone : a.bones) prepared->rest_distance[bone.name] = nullptr;
  // Anchors of every element, and the bones' rest signed distances.
  parallel_for(elements.size(), options.threads, [&](std::size_t e) {
    const std::string& element = elements[e];
    const mesh::IndexedMesh& full = full_mesh(prepared->meshes, element);
    prepared->anchors.at(element) =
        std::make_unique<AnchorBuilder>(full.V, options.anchor_vertices);
    if (prepared->rest_distance.contains(element)) {
      prepared->rest_distance.at(element) = std::make_unique<mesh::SignedDistance>(full);
    }
    for (const auto& [level, surface] : prepared->meshes.at(element)) {
      if (level == "full") continue;
      std::vector<AffineAnchor>& anchors = prepared->level_anchors.at(element)[level];
      anchors.reserve(static_cast<std::size_t>(surface.V.rows()));
      for (Eigen::Index i = 0; i < surface.V.rows(); ++i) {
        anchors.push_back(prepared->anchors.at(element)->anchor(surface.V.row(i).transpose()));
      }
    }
  });
  // Cartilages and ligaments: anchored on their bones.
  for (const atlas::Structure& structure : a.structures) prepared->structures[structure.name];
  parallel_for(a.structures.size(), options.threads, [&](std::size_t s) {
    const atlas::Structure& structure = a.structures[s];
    const Eigen::MatrixX3d& rest = full_mesh(prepared->meshes, structure.name).V;
    PreparedStructure& target = prepared->structures.at(structure.name);
    std::vector<const mesh::SignedDistance*> bones;
    for (const std::string& bone : structure.bones) {
      bones.push_back(prepared->rest_distance.at(bone).get());
      std::vector<AffineAnchor>& anchors = target.on_bones.emplace_back();
      anchors.reserve(static_cast<std::size_t>(rest.rows()));
      for (Eigen::Index i = 0; i < rest.rows(); ++i) {
        anchors.push_back(prepared->anchors.at(bone)->anchor(rest.row(i).transpose()));
      }
    }
    target.weights = atlas::carriage_weights(structure, rest, bones);
  });
  prepared->anchors_seconds = seconds_since(start);
  std::vector<BoneAtRest> bones;
  for (const atlas::Bone& bone : a.bones) {
    bones.push_back({bone.name, &full_mesh(prepared->meshes, bone.name),
                     &coarsest_mesh(prepared->meshes, bone), prepared->anchors.at(bone.name).get(),
                     prepared->rest_distance.at(bone.name).get()});
  }
  prepared->muscles.resize(a.muscles.size());
  parallel_for(a.muscles.size(), options.threads, [&](std::size_t m) {
    const std::string& name = a.muscles[m].name;
    prepared->muscles[m] =
        prepare_muscle(name, full_mesh(prepared->meshes, name), bones, options.muscle);
  });
  prepared->prepare_seconds = seconds_since(start);
  return prepared;
}

namespace {

// The placed full surfaces and affine parts of the bones, filled in chain order.
struct PlacedBones {
  std::map<std::string, Eigen::MatrixX3d> vertices;
  std::map<std::string, Affine3d> affine;
  std::map<std::string, LocalField> local;  // step 1b's field, shared with welded bones
};

bool is_local(const atlas::Landmark& landmark) {
  return std::ranges::find(landmark.tags, "local") != landmark.tags.end();
}

std::vector<PointTerm> bone_terms(const PreparedAtlas& prepared, const atlas::Bone& bone,
                                  const landmarks::LandmarkSet& set, const ScalingEstimate& first,
                                  const PlacedBones& placed, const AtlasScalingOptions& options) {
  const atlas::Atlas& a = prepared.atlas;
  const AnchorBuilder& anchors = *prepared.anchors.at(bone.name);
  std::vector<PointTerm> terms;
  for (const landmarks::Landmark& given : set.landmarks) {
    const atlas::Landmark* landmark = a.find_landmark(given.name);
    // Landmarks on bones welded to this one (the sacrum to the pelvis, the
    // fibula and patella to the tibia) are its terms too: those bones move
    // with its affine part.
    if (landmark == nullptr || moving_with(a, landmark->bone) != bone.name) continue;
    terms.push_back({"landmark " + given.name, anchors.anchor(landmark->position),
                     landmark->position, given.position_mm, options.landmark_weight,
                     is_local(*landmark) ? options.local_radius_mm : 0.0});
  }
  // Proximal joint: where the (already placed) parent puts the joint centre.
  if (const atlas::Joint* joint = joint_to(a, bone.name)) {
    const Vector3d centre = joint->child_frame.translation();
    const Vector3d target = reconstruct(prepared.anchors.at(joint->parent)->anchor(centre),
                                        placed.vertices.at(joint->parent));
    terms.push_back(
        {"joint " + joint->name, anchors.anchor(centre), centre, target, options.joint_weight});
  }
  // Distal joints: where the first stage puts them, weakly — a prior for
  // what the bone's own landmarks leave open, not a rival of them (the child
  // then hangs from wherever this bone puts the joint).
  for (const atlas::Joint& joint : a.joints) {
    if (joint.parent != bone.name || joint.type == atlas::JointType::kWeld) continue;
    const Vector3d centre = joint.child_frame.translation();
    terms.push_back({"joint " + joint.name, anchors.anchor(centre), centre,
                     first.deformation.bone_maps.at(joint.child) * centre,
                     options.distal_joint_weight});
  }
  return terms;
}

BoneScaling describe_bone(const atlas::Atlas& a, const atlas::Bone& bone, const Affine3d& affine) {
  BoneScaling out;
  out.bone = bone.name;
  out.affine = affine;
  // Singular values of the linear part, from the eigenvalues of M^T M
  // (ascending), largest first.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(affine.linear().transpose() *
                                                             affine.linear());
  out.stretches = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().reverse();
  const atlas::Joint* joint = joint_to(a, bone.name);
  const std::optional<Vector3d> distal = atlas::distal_joint_centre(a, bone.name);
  if (joint != nullptr && distal && (*distal - joint->child_frame.translation()).norm() > 1.0) {
    const Vector3d axis = (*distal - joint->child_frame.translation()).normalized();
    out.length_factor = (affine.linear() * axis).norm();
  } else {
    out.length_factor = 0.0;
  }
  return out;
}

std::string direction_name(const Vector3d& direction) {
  Eigen::Index axis = 0;
  direction.cwiseAbs().maxCoeff(&axis);
  return axis == 0 ? "medio-lateral (x)" : axis == 1 ? "antero-posterior (y)" : "vertical (z)";
}

// The stretches of `bone` relative to the first stage's linear part M0, and
// a warning for every one outside the options' range.
void measure_stretch(BoneScaling& bone, const Eigen::Matrix3d& first_stage, const LocalField& local,
                     const Eigen::MatrixX3d& rest, const AtlasScalingOptions& options,
                     std::vector<StretchWarning>& warnings) {
  const Eigen::Matrix3d first_inverse = first_stage.inverse();
  const auto outside = [&](double factor) {
    return factor < options.stretch_min || factor > options.stretch_max;
  };
  const auto warn = [&](const std::string& part, const Vector3d& direction, double factor) {
    StretchWarning warning{bone.bone, part, direction_name(direction), factor, ""};
    std::ostringstream text;
    text.precision(3);
    text << bone.bone << ": " << (part == "affine" ? "the whole bone" : "near its local landmarks")
         << " is stretched x" << factor << " in the " << warning.direction
         << " direction relative to the first stage (plausible " << options.stretch_min << "-"
         << options.stretch_max << "); check the landmarks on it";
    warning.message = text.str();
    warnings.push_back(std::move(warning));
  };
  const Eigen::JacobiSVD<Eigen::Matrix3d> affine(bone.affine.linear() * first_inverse,
                                                 Eigen::ComputeFullU);
  bone.stretch_vs_first_stage = affine.singularValues();
  for (int i = 0; i < 3; ++i) {
    if (outside(affine.singularValues()[i])) {
      warn("affine", affine.matrixU().col(i), affine.singularValues()[i]);
    }
  }
  if (local.empty()) return;
  double lowest = 1.0;
  double highest = 1.0;
  Vector3d low_direction = Vector3d::UnitX();
  Vector3d high_direction = Vector3d::UnitX();
  for (Eigen::Index v = 0; v < rest.rows(); ++v) {
    const Vector3d point = rest.row(v).transpose();
    const Eigen::Matrix3d gradient = local.gradient(point);
    if (gradient.isZero(0.0)) continue;
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd((bone.affine.linear() + gradient) * first_inverse,
                                                Eigen::ComputeFullU);
    const Vector3d& sigma = svd.singularValues();
    if (sigma[0] > highest) {
      highest = sigma[0];
      high_direction = svd.matrixU().col(0);
    }
    if (sigma[2] < lowest) {
      lowest = sigma[2];
      low_direction = svd.matrixU().col(2);
    }
  }
  bone.local_stretch_min = lowest;
  bone.local_stretch_max = highest;
  if (outside(highest)) warn("local", high_direction, highest);
  if (outside(lowest)) warn("local", low_direction, lowest);
}

void place_elements(const PreparedAtlas& prepared, const BonePlacement& placed,
                    ScaledAtlas& scaled) {
  const atlas::Atlas& a = prepared.atlas;
  atlas::PatientDeformation maps;
  maps.bone_maps = placed.affine;
  scaled.atlas = atlas::deform_atlas(a, maps);
  // Positions: reconstructed from the placed surfaces (equal to the affine
  // maps' unless a bone bends).
  const auto on_bone = [&](const std::string& bone, const Vector3d& point) {
    return reconstruct(prepared.anchors.at(bone)->anchor(point), placed.vertices.at(bone));
  };
  atlas::Atlas& out = scaled.atlas;
  for (std::size_t b = 0; b < a.bones.size(); ++b) {
    out.bones[b].frame.translation() = on_bone(a.bones[b].name, a.bones[b].frame.translation());
  }
  for (std::size_t j = 0; j < a.joints.size(); ++j) {
    const atlas::Joint& joint = a.joints[j];
    out.joints[j].parent_frame.translation() =
        on_bone(joint.parent, joint.parent_frame.translation());
    out.joints[j].child_frame.translation() = on_bone(joint.child, joint.child_frame.translation());
  }
  for (std::size_t m = 0; m < a.muscles.size(); ++m) {
    const atlas::Muscle& muscle = a.muscles[m];
    atlas::Muscle& target = out.muscles[m];
    for (std::size_t l = 0; l < muscle.action_lines.size(); ++l) {
      for (std::size_t p = 0; p < muscle.action_lines[l].points.size(); ++p) {
        const atlas::PathPoint& point = muscle.action_lines[l].points[p];
        target.action_lines[l].points[p].position = on_bone(point.bone, point.position);
      }
    }
    const auto areas = [&](const std::vector<atlas::AttachmentArea>& from,
                           std::vector<atlas::AttachmentArea>& to) {
      for (std::size_t i = 0; i < from.size(); ++i) {
        to[i].centroid = on_bone(from[i].bone, from[i].centroid);
        const mesh::IndexedMesh bone{placed.vertices.at(from[i].bone),
                                     full_mesh(prepared.meshes, from[i].bone).F};
        if (!from[i].faces.empty()) to[i].area_mm2 = face_area_sum(bone, from[i].faces);
      }
    };
    areas(muscle.origins, target.origins);
    areas(muscle.insertions, target.insertions);
    for (std::size_t w = 0; w < muscle.wrap_obstacles.size(); ++w) {
      const atlas::WrapObstacle& obstacle = muscle.wrap_obstacles[w];
      target.wrap_obstacles[w].pose.translation() =
          on_bone(obstacle.bone, obstacle.pose.translation());
    }
  }
  for (std::size_t i = 0; i < a.landmarks.size(); ++i) {
    out.landmarks[i].position = on_bone(a.landmarks[i].bone, a.landmarks[i].position);
  }
  for (std::size_t i = 0; i < a.markers.size(); ++i) {
    out.markers[i].position = on_bone(a.markers[i].bone, a.markers[i].position);
  }
}

}  // namespace

ScaledAtlas scale_atlas(const PreparedAtlas& prepared, const landmarks::LandmarkSet& landmarks,
                        const AtlasScalingOptions& options) {
  const Clock::time_point start = Clock::now();
  const atlas::Atlas& a = prepared.atlas;
  ScaledAtlas scaled;
  scaled.first_stage = estimate_anatomical_scaling(a, landmarks, options.anatomical);
  scaled.notes = scaled.first_stage.notes;
  for (const landmarks::Landmark& given : landmarks.landmarks) {
    if (a.find_landmark(given.name) == nullptr) scaled.unused_landmarks.push_back(given.name);
  }
  if (!scaled.unused_landmarks.empty()) {
    std::string names;
    for (const std::string& name : scaled.unused_landmarks)
      names += (names.empty() ? "" : ", ") + name;
    scaled.notes.push_back("landmarks not in the atlas, not used: " + names);
  }
  scaled.timings.anatomical_s = seconds_since(start);

  // Bones, root first.
  Clock::time_point stage = Clock::now();
  PlacedBones placed;
  for (const atlas::Bone* bone : chain_order(a, "atlas scaling")) {
    const atlas::Joint* joint = joint_to(a, bone->name);
    const mesh::IndexedMesh& rest = full_mesh(prepared.meshes, bone->name);
    BoneScaling report;
    if (joint != nullptr && joint->type == atlas::JointType::kWeld) {
      const Affine3d& parent = placed.affine.at(joint->parent);
      report = describe_bone(a, *bone, parent);
      report.welded_to = joint->parent;
      placed.affine[bone->name] = parent;
      // The parent's local field too: a malleolus on the fibula moves the
      // fibula's end with the tibia's.
      const LocalField& local = placed.local.at(joint->parent);
      placed.local[bone->name] = local;
      placed.vertices[bone->name] =
          Eigen::MatrixX3d((rest.V * parent.linear().transpose()).rowwise() +
                           parent.translation().transpose()) +
          local.displacements(rest.V);
    } else {
      const std::vector<PointTerm> terms =
          bone_terms(prepared, *bone, landmarks, scaled.first_stage, placed, options);
      BoneSolution solution = solve_bone(
          rest, scaled.first_stage.deformation.bone_maps.at(bone->name), terms, options.bone);
      report = describe_bone(a, *bone, solution.affine);
      report.solved = solution.solved;
      report.bent = solution.bent;
      report.free_directions = solution.free_directions;
      for (const PointTerm& term : terms) {
        report.terms.push_back(term.name);
        if (term.falloff_radius_mm > 0.0) ++report.local_points;
      }
      report.term_residual_mm = solution.residual_mm;
      measure_stretch(report, scaled.first_stage.deformation.bone_maps.at(bone->name).linear(),
                      solution.local, rest.V, options, scaled.warnings);
      placed.local[bone->name] = std::move(solution.local);
      placed.affine[bone->name] = solution.affine;
      placed.vertices[bone->name] = std::move(solution.vertices);
    }
    scaled.bones.push_back(std::move(report));
  }
  scaled.timings.bones_s = seconds_since(stage);
  carry_atlas(prepared, BonePlacement{std::move(placed.vertices), std::move(placed.affine)},
              options, scaled);
  for (const landmarks::Landmark& given : landmarks.landmarks) {
    for (const atlas::Landmark& landmark : scaled.atlas.landmarks) {
      if (landmark.name == given.name) {
        scaled.landmark_residual_mm[given.name] = (landmark.position - given.position_mm).norm();
      }
    }
  }
  scaled.atlas.provenance.push_back(
      "scaled by mmm scale_atlas onto " + std::to_string(landmarks.landmarks.size()) +
      " landmarks (" + (landmarks.source.empty() ? "unknown source" : landmarks.source) +
      ", frame " + landmarks.frame + ")");
  scaled.timings.total_s = seconds_since(start);
  return scaled;
}

void carry_atlas(const PreparedAtlas& prepared, const BonePlacement& placed,
                 const AtlasScalingOptions& options, ScaledAtlas& scaled) {
  const atlas::Atlas& a = prepared.atlas;
  Clock::time_point stage = Clock::now();
  for (const atlas::Bone& bone : a.bones) {
    if (!placed.vertices.contains(bone.name) || !placed.affine.contains(bone.name)) {
      throw InvalidInputError("carrying the atlas: bone '" + bone.name +
                              "' has no placement; hint: place every bone of the atlas");
    }
    if (placed.vertices.at(bone.name).rows() != full_mesh(prepared.meshes, bone.name).V.rows()) {
      throw InvalidInputError("carrying the atlas: bone '" + bone.name + "' is placed with " +
                              std::to_string(placed.vertices.at(bone.name).rows()) +
                              " vertices, its full mesh has " +
                              std::to_string(full_mesh(prepared.meshes, bone.name).V.rows()));
    }
  }
  for (const atlas::Bone& bone : a.bones) {
    std::map<std::string, mesh::IndexedMesh>& levels = scaled.meshes[bone.name];
    for (const auto& [level, surface] : prepared.meshes.at(bone.name)) {
      levels[level].F = surface.F;
      levels[level].V = level == "full"
                            ? placed.vertices.at(bone.name)
                            : reconstruct_all(prepared.level_anchors.at(bone.name).at(level),
                                              placed.vertices.at(bone.name));
    }
  }
  for (const atlas::Structure& structure : a.structures) {
    const PreparedStructure& carriage = prepared.structures.at(structure.name);
    const mesh::IndexedMesh& rest = full_mesh(prepared.meshes, structure.name);
    Eigen::MatrixX3d full = Eigen::MatrixX3d::Zero(rest.V.rows(), 3);
    for (std::size_t b = 0; b < structure.bones.size(); ++b) {
      const Eigen::MatrixX3d& bone = placed.vertices.at(structure.bones[b]);
      for (Eigen::Index i = 0; i < rest.V.rows(); ++i) {
        full.row(i) +=
            carriage.weights(i, static_cast<Eigen::Index>(b)) *
            reconstruct(carriage.on_bones[b][static_cast<std::size_t>(i)], bone).transpose();
      }
    }
    std::map<std::string, mesh::IndexedMesh>& levels = scaled.meshes[structure.name];
    for (const auto& [level, surface] : prepared.meshes.at(structure.name)) {
      levels[level].F = surface.F;
      levels[level].V =
          level == "full"
              ? full
              : reconstruct_all(prepared.level_anchors.at(structure.name).at(level), full);
    }
  }
  scaled.timings.bones_s += seconds_since(stage);

  // Muscles.
  stage = Clock::now();
  std::vector<std::unique_ptr<mesh::SignedDistance>> distance(a.bones.size());
  parallel_for(a.bones.size(), options.threads, [&](std::size_t b) {
    distance[b] =
        std::make_unique<mesh::SignedDistance>(scaled.meshes.at(a.bones[b].name).at("full"));
  });
  std::vector<ScaledBone> bones;
  for (std::size_t b = 0; b < a.bones.size(); ++b) {
    bones.push_back({&placed.affine.at(a.bones[b].name), &placed.vertices.at(a.bones[b].name),
                     distance[b].get()});
  }
  scaled.muscles.resize(a.muscles.size());
  for (const atlas::Muscle& muscle : a.muscles) scaled.meshes[muscle.name];
  parallel_for(a.muscles.size(), options.threads, [&](std::size_t m) {
    const std::string& name = a.muscles[m].name;
    scaled.muscles[m].muscle = name;
    scaled.muscles[m].solution = solve_muscle(prepared.muscles[m], bones, options.muscle);
  });
  for (std::size_t m = 0; m < a.muscles.size(); ++m) {
    const std::string& name = a.muscles[m].name;
    std::map<std::string, mesh::IndexedMesh>& levels = scaled.meshes.at(name);
    const Eigen::MatrixX3d& vertices = scaled.muscles[m].solution.vertices;
    for (const auto& [level, surface] : prepared.meshes.at(name)) {
      levels[level].F = surface.F;
      levels[level].V = level == "full"
                            ? vertices
                            : reconstruct_all(prepared.level_anchors.at(name).at(level), vertices);
    }
  }
  scaled.timings.muscles_s = seconds_since(stage);

  stage = Clock::now();
  place_elements(prepared, placed, scaled);
  scaled.timings.elements_s = seconds_since(stage);
}

nlohmann::json scaling_report_json(const ScaledAtlas& scaled) {
  using nlohmann::json;
  json report;
  report["landmark_residual_mm"] = scaled.landmark_residual_mm;
  report["unused_landmarks"] = scaled.unused_landmarks;
  report["notes"] = scaled.notes;
  json warnings = json::array();
  for (const StretchWarning& warning : scaled.warnings) {
    warnings.push_back({{"bone", warning.bone},
                        {"part", warning.part},
                        {"direction", warning.direction},
                        {"factor", warning.factor},
                        {"message", warning.message}});
  }
  report["warnings"] = warnings;
  // The final per-bone length factors (after the energy), beside the first
  // stage's per-segment ones below.
  json final_factors = json::object();
  for (const BoneScaling& bone : scaled.bones) {
    if (bone.length_factor > 0.0 && bone.welded_to.empty()) {
      final_factors[bone.bone] = bone.length_factor;
    }
  }
  report["length_factor"] = final_factors;
  const ScalingEstimate& first = scaled.first_stage;
  report["first_stage"] = {{"stature_scale", first.stature_scale},
                           {"knee_rotation_deg", first.knee_rotation_deg},
                           {"segment_length_factor", first.segment_length_factor},
                           {"landmark_residual_mm", first.landmark_residual_mm}};
  json bones = json::array();
  for (const BoneScaling& bone : scaled.bones) {
    json entry = {{"bone", bone.bone},
                  {"solve", !bone.welded_to.empty() ? "welded to " + bone.welded_to
                            : bone.bent   ? "affine fit + Laplacian detail (sparse Cholesky)"
                            : bone.solved ? "affine fit"
                                          : "first stage (meets every term)"},
                  {"affine_directions_from_first_stage", bone.free_directions},
                  {"stretches", {bone.stretches.x(), bone.stretches.y(), bone.stretches.z()}},
                  {"stretch_vs_first_stage",
                   {bone.stretch_vs_first_stage.x(), bone.stretch_vs_first_stage.y(),
                    bone.stretch_vs_first_stage.z()}},
                  {"volume_scale", bone.affine.linear().determinant()}};
    if (bone.local_points > 0) {
      entry["local_landmarks"] = bone.local_points;
      entry["local_stretch_range"] = {bone.local_stretch_min, bone.local_stretch_max};
    }
    if (bone.length_factor > 0.0) entry["length_factor"] = bone.length_factor;
    json terms = json::array();
    for (std::size_t t = 0; t < bone.terms.size(); ++t) {
      terms.push_back({{"term", bone.terms[t]}, {"residual_mm", bone.term_residual_mm[t]}});
    }
    entry["terms"] = terms;
    bones.push_back(entry);
  }
  report["bones"] = bones;
  json muscles = json::array();
  for (const MuscleScaling& muscle : scaled.muscles) {
    const MuscleSolution& s = muscle.solution;
    muscles.push_back({{"muscle", muscle.muscle},
                       {"volume_ratio", s.volume_ratio},
                       {"attached_vertices", s.attached_vertices},
                       {"band_vertices", s.band_vertices},
                       {"attachment_rms_mm", s.attachment_rms_mm},
                       {"penetration_iterations", s.penetration_iterations},
                       {"penetrating_vertices_before", s.penetrating_before},
                       {"excess_depth_before_mm", s.excess_depth_before_mm},
                       {"penetrating_vertices_after", s.penetrating_after},
                       {"excess_depth_after_mm", s.excess_depth_after_mm}});
  }
  report["muscles"] = muscles;
  report["timings_s"] = {{"anatomical", scaled.timings.anatomical_s},
                         {"bones", scaled.timings.bones_s},
                         {"muscles", scaled.timings.muscles_s},
                         {"elements", scaled.timings.elements_s},
                         {"total", scaled.timings.total_s}};
  return report;
}

}  // namespace mmm::scaling

#include "core/atlas/patient_deformation.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numbers>

#include "core/atlas/bone_registration.h"
#include "core/atlas/kinematic_chain.h"
#include "core/errors.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::atlas {
namespace {

constexpr double kClipSigmas = 2.5;

double draw(std::mt19937_64& random, double sd) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const double z = std::clamp(normal(random), -kClipSigmas, kClipSigmas);
  return 1.0 + sd * z;
}

Eigen::Isometry3d map_frame(const Eigen::Affine3d& map, const Eigen::Isometry3d& frame) {
  Eigen::Isometry3d mapped = Eigen::Isometry3d::Identity();
  mapped.linear() = nearest_rotation(map.linear()) * frame.linear();
  mapped.translation() = map * frame.translation();
  return mapped;
}

double length_scale(const Eigen::Affine3d& map) {
  return std::cbrt(std::abs(map.linear().determinant()));
}

opensim::Function length_scaled(const opensim::Function& function, double factor) {
  return opensim::MultiplierFunction(function, factor);
}

}  // namespace

Eigen::Vector3d NeckWarp::apply(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d offset = point - head;
  const double neck_length = (pivot - head).norm();
  const double across = std::clamp(1.0 - offset.dot(lateral) / neck_length, 0.0, 1.0);
  const double down = std::clamp(2.0 - offset.dot(distal) / 30.0, 0.0, 1.0);
  const Eigen::AngleAxisd turn(across * down * angle_rad, axis);
  return pivot + turn * (point - pivot) + shift;
}

Eigen::Vector3d PatientDeformation::map_on_bone(const std::string& bone,
                                                const Eigen::Vector3d& point) const {
  const auto map = bone_maps.find(bone);
  if (map == bone_maps.end()) {
    throw InvalidInputError("patient deformation: no map for bone '" + bone + "'");
  }
  Eigen::Vector3d warped = point;
  if (const auto warp = local.find(bone); warp != local.end()) warped = warp->second.apply(warped);
  return map->second * (bone == neck.bone ? neck.apply(warped) : warped);
}

Eigen::Vector3d LocalWarp::apply(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d offset = point - proximal;
  const double t = offset.dot(axis);
  const double s = std::clamp(t / length, 0.0, 1.0);
  Eigen::Vector3d out = proximal + Eigen::AngleAxisd(s * torsion_rad, axis) * offset;
  out += std::sin(std::numbers::pi * s) * bow;
  const Eigen::Vector3d radial = offset - t * axis;
  if (radial.norm() > 1e-9 && !bumps.empty()) {
    const Eigen::Vector3d r = radial.normalized();
    const double phi = std::atan2(axis.cross(reference).dot(r), reference.dot(r));
    for (const Bump& bump : bumps) {
      const double d_phi = std::remainder(phi - bump.angle_rad, 2 * std::numbers::pi);
      const double along = (t - bump.along_mm) / bump_length_mm;
      const double around = d_phi / bump_angle_rad;
      out += bump.height_mm * std::exp(-0.5 * (along * along + around * around)) * r;
    }
  }
  return out;
}

namespace {

// The femur: a child of the root, whose joint has three coordinates, with a
// distal joint. Sets up the warp's geometry; the angle is set by the caller.
NeckWarp neck_warp_for(const Atlas& atlas, const Bone& root) {
  NeckWarp warp;
  for (const Joint& joint : atlas.joints) {
    if (joint.parent != root.name || joint.coordinates.size() != 3) continue;
    const Joint* distal = nullptr;
    for (const Joint& child : atlas.joints) {
      if (child.parent == joint.child && child.type != JointType::kWeld) distal = &child;
    }
    if (distal == nullptr) continue;
    warp.bone = joint.child;
    warp.head = joint.child_frame.translation();
    warp.distal = (distal->child_frame.translation() - warp.head).normalized();
    // Lateral: away from the root's mid-plane, across the bone.
    const double side = warp.head.x() >= root.frame.translation().x() ? 1.0 : -1.0;
    Eigen::Vector3d lateral = side * Eigen::Vector3d::UnitX();
    lateral -= lateral.dot(warp.distal) * warp.distal;
    warp.lateral = lateral.normalized();
    warp.axis = warp.distal.cross(warp.lateral).normalized();
    warp.pivot = warp.head + 45.0 * warp.lateral;
    return warp;
  }
  return warp;
}

}  // namespace

PatientDeformation make_patient_deformation(const Atlas& atlas, const PatientOptions& options) {
  PatientDeformation deformation;
  PatientFactors& factors = deformation.factors;
  factors.seed = options.seed;
  std::mt19937_64 random(options.seed);
  factors.stature_scale = draw(random, options.stature_sd);
  if (options.height_mm) factors.stature_scale = *options.height_mm / options.atlas_height_mm;
  factors.height_mm = factors.stature_scale * options.atlas_height_mm;
  if (!(factors.height_mm >= 1000.0 && factors.height_mm <= 2300.0)) {
    throw InvalidInputError("patient height " + std::to_string(factors.height_mm) +
                            " mm is outside the human range 1000-2300 mm");
  }
  factors.pelvis_width = draw(random, options.pelvis_width_sd);
  // Factors drawn in atlas order, so a seed gives the same patient whatever
  // the joint layout.
  for (const Bone& bone : atlas.bones) {
    factors.length[bone.name] = draw(random, options.segment_length_sd);
    factors.width[bone.name] = draw(random, options.width_sd);
  }
  const double s = factors.stature_scale;
  // Drawn after the other factors, so that adding it left every earlier
  // seed's proportions as they were. draw() gives 1 + sd z (z clipped).
  factors.neck_angle_deg = (draw(random, options.neck_angle_sd_deg / 100.0) - 1.0) * 100.0;

  const std::vector<const Bone*> order = chain_order(atlas, "patient deformation");
  if (options.local_shape) {
    // Drawn last, in atlas order, so that earlier factors do not change.
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> uniform;
    for (const Bone& bone : atlas.bones) {
      const Joint* joint = joint_to(atlas, bone.name);
      const std::optional<Eigen::Vector3d> distal = distal_joint_centre(atlas, bone.name);
      if (joint == nullptr || joint->type == JointType::kWeld || !distal) continue;
      const Eigen::Vector3d proximal = joint->child_frame.translation();
      if ((*distal - proximal).norm() < 150.0) continue;  // long bones only
      LocalWarp warp;
      warp.proximal = proximal;
      warp.length = (*distal - proximal).norm();
      warp.axis = (*distal - proximal) / warp.length;
      warp.reference = (Eigen::Vector3d::UnitX() - warp.axis.x() * warp.axis).normalized();
      const auto clipped = [&] { return std::clamp(normal(random), -2.5, 2.5); };
      warp.torsion_rad = clipped() * options.torsion_sd_deg * std::numbers::pi / 180.0;
      const Eigen::Vector3d across = warp.axis.cross(warp.reference);
      warp.bow = options.bowing_sd_mm * (clipped() * warp.reference + clipped() * across);
      warp.bump_length_mm = options.bump_length_mm;
      warp.bump_angle_rad = options.bump_angle_deg * std::numbers::pi / 180.0;
      for (int k = 0; k < options.bumps_per_bone; ++k) {
        LocalWarp::Bump bump;
        bump.along_mm = (0.15 + 0.7 * uniform(random)) * warp.length;
        bump.angle_rad = (2.0 * uniform(random) - 1.0) * std::numbers::pi;
        bump.height_mm = clipped() * options.bump_sd_mm;
        warp.bumps.push_back(bump);
      }
      factors.torsion_deg[bone.name] = warp.torsion_rad * 180.0 / std::numbers::pi;
      factors.bowing_mm[bone.name] = warp.bow.norm();
      deformation.local[bone.name] = warp;
    }
  }
  const Bone* root = order.front();
  deformation.neck = neck_warp_for(atlas, *root);
  if (!deformation.neck.bone.empty()) {
    NeckWarp& neck = deformation.neck;
    neck.angle_rad = factors.neck_angle_deg * std::numbers::pi / 180.0;
    neck.shift = neck.head - neck.apply(neck.head);
  }
  for (const Bone* bone : order) {
    const Joint* joint = joint_to(atlas, bone->name);
    Eigen::Affine3d map = Eigen::Affine3d::Identity();
    if (joint == nullptr) {
      // The root, or a bone without a joint: scales about the root's origin.
      const Eigen::Vector3d origin = root->frame.translation();
      Eigen::Matrix3d linear = s * Eigen::Matrix3d::Identity();
      linear(0, 0) *= factors.pelvis_width;
      map.linear() = linear;
      map.translation() = origin - linear * origin;
      if (bone != root) map = deformation.bone_maps.at(root->name);
    } else if (joint->type == JointType::kWeld) {
      map = deformation.bone_maps.at(joint->parent);
    } else {
      const Eigen::Vector3d proximal = joint->child_frame.translation();
      const std::optional<Eigen::Vector3d> distal = distal_joint_centre(atlas, bone->name);
      const double length = factors.length.at(bone->name);
      const double width = factors.width.at(bone->name);
      Eigen::Matrix3d linear = s * length * Eigen::Matrix3d::Identity();
      if (distal && (*distal - proximal).norm() > 1.0) {
        const Eigen::Vector3d axis = (*distal - proximal).normalized();
        const Eigen::Matrix3d along = axis * axis.transpose();
        linear = s * (length * along + width * (Eigen::Matrix3d::Identity() - along));
      }
      const Eigen::Vector3d moved = deformation.map_on_bone(joint->parent, proximal);
      map.linear() = linear;
      map.translation() = moved - linear * proximal;
    }
    deformation.bone_maps[bone->name] = map;
  }
  return deformation;
}

Atlas deform_atlas(const Atlas& atlas, const PatientDeformation& deformation) {
  Atlas patient = atlas;
  const auto& maps = deformation.bone_maps;
  // Frames turn with their bone's affine map; their origins go where the
  // points of the bone go (the neck warp included).
  const auto frame_on = [&](const std::string& bone, const Eigen::Isometry3d& frame) {
    Eigen::Isometry3d mapped = map_frame(maps.at(bone), frame);
    mapped.translation() = deformation.map_on_bone(bone, frame.translation());
    return mapped;
  };
  for (Bone& bone : patient.bones) bone.frame = frame_on(bone.name, bone.frame);
  for (Joint& joint : patient.joints) {
    const Eigen::Affine3d& parent = maps.at(joint.parent);
    joint.parent_frame = frame_on(joint.parent, joint.parent_frame);
    joint.child_frame = frame_on(joint.child, joint.child_frame);
    for (TransformAxis& axis : joint.axes) {
      if (!axis.rotation) axis.function = length_scaled(axis.function, length_scale(parent));
    }
  }
  for (Muscle& muscle : patient.muscles) {
    for (ActionLine& line : muscle.action_lines) {
      for (PathPoint& point : line.points) {
        const Eigen::Affine3d& map = maps.at(point.bone);
        point.position = deformation.map_on_bone(point.bone, point.position);
        if (point.kind == PathPointKind::kMoving) {
          for (opensim::Function& function : point.moving_functions) {
            function = length_scaled(function, length_scale(map));
          }
        }
      }
    }
    for (auto* areas : {&muscle.origins, &muscle.insertions}) {
      for (AttachmentArea& area : *areas) {
        const Eigen::Affine3d& map = maps.at(area.bone);
        area.centroid = deformation.map_on_bone(area.bone, area.centroid);
        area.area_mm2 *= std::pow(length_scale(map), 2);
      }
    }
    for (WrapObstacle& obstacle : muscle.wrap_obstacles) {
      const Eigen::Affine3d& map = maps.at(obstacle.bone);
      obstacle.pose = frame_on(obstacle.bone, obstacle.pose);
      obstacle.radii *= length_scale(map);
    }
  }
  for (Landmark& landmark : patient.landmarks) {
    landmark.position = deformation.map_on_bone(landmark.bone, landmark.position);
  }
  for (Marker& marker : patient.markers) {
    marker.position = deformation.map_on_bone(marker.bone, marker.position);
  }
  return patient;
}

mesh::IndexedMesh deform_bone_mesh(const PatientDeformation& deformation, const std::string& bone,
                                   const mesh::IndexedMesh& surface) {
  mesh::IndexedMesh mapped = surface;
  for (Eigen::Index i = 0; i < mapped.V.rows(); ++i) {
    mapped.V.row(i) =
        deformation.map_on_bone(bone, Eigen::Vector3d(surface.V.row(i).transpose())).transpose();
  }
  return mapped;
}

mesh::IndexedMesh deform_muscle_mesh(const PatientDeformation& deformation,
                                     const std::map<std::string, mesh::IndexedMesh>& bones,
                                     const mesh::IndexedMesh& surface, double blend_radius_mm) {
  if (bones.empty()) throw InvalidInputError("deform_muscle_mesh: no bone surfaces given");
  std::vector<std::pair<std::string, mesh::AabbTree>> trees;
  trees.reserve(bones.size());
  for (const auto& [name, bone] : bones) {
    if (!deformation.bone_maps.contains(name)) {
      throw InvalidInputError("deform_muscle_mesh: no map for bone '" + name + "'");
    }
    trees.emplace_back(name, mesh::AabbTree(bone));
  }
  const double eps2 = blend_radius_mm * blend_radius_mm;
  mesh::IndexedMesh mapped = surface;
  for (Eigen::Index i = 0; i < surface.V.rows(); ++i) {
    const Eigen::Vector3d p = surface.V.row(i).transpose();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double total = 0.0;
    for (const auto& [name, tree] : trees) {
      const double weight = 1.0 / (tree.closest_point(p).squared_distance + eps2);
      sum += weight * deformation.map_on_bone(name, p);
      total += weight;
    }
    mapped.V.row(i) = (sum / total).transpose();
  }
  return mapped;
}

}  // namespace mmm::atlas

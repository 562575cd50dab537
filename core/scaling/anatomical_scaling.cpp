#include "core/scaling/anatomical_scaling.h"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/fit/rigid_fit.h"

namespace mmm::scaling {
namespace {

using Eigen::Affine3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

// The patient's landmarks the estimate uses.
struct Targets {
  Vector3d head;
  Vector3d patella;
  std::optional<Vector3d> ankle;
};

// The atlas's side: landmarks, the bones in chain order, segment axes.
struct Skeleton {
  std::vector<const atlas::Bone*> order;             // each after its parent; the root first
  std::map<std::string, const atlas::Joint*> joint;  // bone -> joint from its parent
  std::map<std::string, Vector3d> axis;              // bone -> unit long axis (when it has one)
  std::string root;
  std::string femur;
  std::string tibia;
  const atlas::Landmark* head = nullptr;
  const atlas::Landmark* patella = nullptr;
  const atlas::Landmark* ankle = nullptr;  // only when the patient has one
};

// The shape parameters (G = identity).
struct Shape {
  double femur_length = 1.0;
  double tibia_length = 1.0;
  double knee_angle_rad = 0.0;
  Vector3d knee_axis = Vector3d::UnitX();

  [[nodiscard]] double stature() const { return 0.5 * (femur_length + tibia_length); }
};

using BoneMaps = std::map<std::string, Affine3d>;

std::string joined(const std::vector<std::string>& names) {
  if (names.empty()) return "(none)";
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

Targets read_targets(const landmarks::LandmarkSet& set, const ScalingOptions& options,
                     std::string_view what) {
  try {
    landmarks::validate_landmark_set(set);
  } catch (const InvalidInputError& error) {
    throw InvalidInputError(std::string(what) + ": patient landmarks: " + error.what());
  }
  const auto required = [&](std::string_view name) {
    const landmarks::Landmark* landmark = set.find(name);
    if (landmark == nullptr) {
      throw InvalidInputError(std::string(what) + ": the patient landmarks lack '" +
                              std::string(name) + "' (required: " + std::string(kFemoralHead) +
                              ", " + std::string(kPatella) + "; optional: " + std::string(kAnkle) +
                              "); present: " + joined(set.names()));
    }
    return landmark->position_mm;
  };
  Targets targets{required(kFemoralHead), required(kPatella), std::nullopt};
  if (const landmarks::Landmark* ankle = set.find(kAnkle)) targets.ankle = ankle->position_mm;
  const auto separated = [&](std::string_view a, const Vector3d& pa, std::string_view b,
                             const Vector3d& pb) {
    const double distance = (pa - pb).norm();
    if (distance < options.min_landmark_distance_mm) {
      std::ostringstream message;
      message << what << ": patient landmarks '" << a << "' and '" << b << "' are " << distance
              << " mm apart (at least " << options.min_landmark_distance_mm
              << " mm needed): check that they were not placed on the same point";
      throw InvalidInputError(message.str());
    }
  };
  separated(kFemoralHead, targets.head, kPatella, targets.patella);
  if (targets.ankle) {
    separated(kPatella, targets.patella, kAnkle, *targets.ankle);
    separated(kFemoralHead, targets.head, kAnkle, *targets.ankle);
  }
  return targets;
}

const atlas::Landmark& atlas_landmark(const atlas::Atlas& atlas, std::string_view name,
                                      std::string_view what) {
  const atlas::Landmark* landmark = atlas.find_landmark(name);
  if (landmark == nullptr) {
    std::vector<std::string> names;
    for (const atlas::Landmark& present : atlas.landmarks) names.push_back(present.name);
    throw InvalidInputError(std::string(what) + ": atlas '" + atlas.name + "' has no landmark '" +
                            std::string(name) + "' (its landmarks: " + joined(names) +
                            "); rebuild the atlas with the station landmarks");
  }
  if (atlas.find_bone(landmark->bone) == nullptr) {
    throw InvalidInputError(std::string(what) + ": atlas landmark '" + landmark->name +
                            "' is on unknown bone '" + landmark->bone + "'");
  }
  return *landmark;
}

// Follows weld joints up to the bone that carries its own map.
std::string segment_of(const Skeleton& skeleton, std::string bone) {
  for (auto joint = skeleton.joint.find(bone);
       joint != skeleton.joint.end() && joint->second->type == atlas::JointType::kWeld;
       joint = skeleton.joint.find(bone)) {
    bone = joint->second->parent;
  }
  return bone;
}

Skeleton read_skeleton(const atlas::Atlas& atlas, bool with_ankle, std::string_view what) {
  Skeleton skeleton;
  skeleton.head = &atlas_landmark(atlas, kFemoralHead, what);
  skeleton.patella = &atlas_landmark(atlas, kPatella, what);
  if (with_ankle) skeleton.ankle = &atlas_landmark(atlas, kAnkle, what);
  for (const atlas::Joint& joint : atlas.joints) {
    if (atlas.find_bone(joint.parent) == nullptr || atlas.find_bone(joint.child) == nullptr) {
      throw InvalidInputError(std::string(what) + ": atlas joint '" + joint.name +
                              "' connects unknown bones '" + joint.parent + "' -> '" + joint.child +
                              "'");
    }
    skeleton.joint[joint.child] = &joint;
  }
  // Chain order: the root (no joint from a parent) first, then each bone
  // after its parent.
  std::set<std::string> placed;
  for (const atlas::Bone& bone : atlas.bones) {
    if (!skeleton.joint.contains(bone.name) && skeleton.root.empty()) {
      skeleton.root = bone.name;
      skeleton.order.push_back(&bone);
      placed.insert(bone.name);
    }
  }
  if (skeleton.root.empty()) {
    throw InvalidInputError(std::string(what) + ": atlas '" + atlas.name +
                            "' has no root bone (every bone hangs from a joint)");
  }
  for (bool progress = true; progress;) {
    progress = false;
    for (const atlas::Bone& bone : atlas.bones) {
      if (placed.contains(bone.name)) continue;
      const auto joint = skeleton.joint.find(bone.name);
      if (joint == skeleton.joint.end() || placed.contains(joint->second->parent)) {
        skeleton.order.push_back(&bone);
        placed.insert(bone.name);
        progress = true;
      }
    }
  }
  if (skeleton.order.size() != atlas.bones.size()) {
    throw InvalidInputError(std::string(what) + ": atlas '" + atlas.name +
                            "' has bones not connected to the root '" + skeleton.root +
                            "' (a cycle of joints?)");
  }
  // Segment axes: proximal joint centre -> mean centre of the distal joints.
  for (const atlas::Bone* bone : skeleton.order) {
    const auto joint = skeleton.joint.find(bone->name);
    if (joint == skeleton.joint.end() || joint->second->type == atlas::JointType::kWeld) continue;
    Vector3d distal = Vector3d::Zero();
    int count = 0;
    for (const atlas::Joint& child : atlas.joints) {
      if (child.parent == bone->name && child.type != atlas::JointType::kWeld) {
        distal += child.child_frame.translation();
        ++count;
      }
    }
    const Vector3d proximal = joint->second->child_frame.translation();
    if (count > 0 && (distal / count - proximal).norm() > 1.0) {
      skeleton.axis[bone->name] = (distal / count - proximal).normalized();
    }
  }
  // The expected structure: femur -> tibia (through a non-weld joint), the
  // patella and ankle landmarks on the tibia's segment.
  skeleton.femur = segment_of(skeleton, skeleton.head->bone);
  skeleton.tibia = segment_of(skeleton, skeleton.patella->bone);
  const auto tibia_joint = skeleton.joint.find(skeleton.tibia);
  if (tibia_joint == skeleton.joint.end() ||
      segment_of(skeleton, tibia_joint->second->parent) != skeleton.femur ||
      !skeleton.axis.contains(skeleton.femur)) {
    throw InvalidInputError(std::string(what) + ": atlas '" + atlas.name + "': landmark '" +
                            std::string(kPatella) + "' is on bone '" + skeleton.patella->bone +
                            "' (segment '" + skeleton.tibia + "'), which does not hang from '" +
                            skeleton.femur + "', the bone of '" + std::string(kFemoralHead) +
                            "'; the estimate expects femur -> tibia (knee) with the patella on "
                            "either (welded)");
  }
  if (skeleton.ankle != nullptr && segment_of(skeleton, skeleton.ankle->bone) != skeleton.tibia) {
    throw InvalidInputError(std::string(what) + ": atlas '" + atlas.name + "': landmark '" +
                            std::string(kAnkle) + "' is on bone '" + skeleton.ankle->bone +
                            "', not on the segment of '" + std::string(kPatella) + "' ('" +
                            skeleton.tibia + "')");
  }
  return skeleton;
}

// The maps of the model with G = identity (see the header).
BoneMaps shape_maps(const Skeleton& skeleton, const Shape& shape) {
  const double s = shape.stature();
  const Matrix3d knee_turn = Eigen::AngleAxisd(shape.knee_angle_rad, shape.knee_axis).matrix();
  BoneMaps maps;
  std::map<std::string, Matrix3d> turn;  // accumulated rotation of each bone
  for (const atlas::Bone* bone : skeleton.order) {
    const auto joint = skeleton.joint.find(bone->name);
    if (joint == skeleton.joint.end()) {
      // The root scales by s (the anchor is G's business).
      maps[bone->name] = Affine3d(Eigen::Scaling(s));
      turn[bone->name] = Matrix3d::Identity();
      continue;
    }
    const atlas::Joint& from_parent = *joint->second;
    if (from_parent.type == atlas::JointType::kWeld) {
      maps[bone->name] = maps.at(from_parent.parent);
      turn[bone->name] = turn.at(from_parent.parent);
      continue;
    }
    Matrix3d rotation = turn.at(from_parent.parent);
    if (bone->name == skeleton.tibia) rotation = rotation * knee_turn;
    double length = s;
    if (bone->name == skeleton.femur) length = shape.femur_length;
    if (bone->name == skeleton.tibia) length = shape.tibia_length;
    Matrix3d stretch = s * Matrix3d::Identity();
    if (const auto axis = skeleton.axis.find(bone->name); axis != skeleton.axis.end()) {
      const Matrix3d along = axis->second * axis->second.transpose();
      stretch = length * along + s * (Matrix3d::Identity() - along);
    }
    const Vector3d centre = from_parent.child_frame.translation();
    Affine3d map = Affine3d::Identity();
    map.linear() = rotation * stretch;
    map.translation() = maps.at(from_parent.parent) * centre - map.linear() * centre;
    maps[bone->name] = map;
    turn[bone->name] = rotation;
  }
  return maps;
}

Vector3d mapped(const BoneMaps& maps, const atlas::Landmark& landmark) {
  return maps.at(landmark.bone) * landmark.position;
}

// The angle between u and v (rad), negative when u x v points against
// `axis` (the sign keeps it smooth through 0 as the knee straightens).
double signed_angle(const Vector3d& u, const Vector3d& v, const Vector3d& axis) {
  const Vector3d normal = u.cross(v);
  return std::atan2(normal.dot(axis) < 0 ? -normal.norm() : normal.norm(), u.dot(v));
}

// Orthonormal frame of the pair (u, v): u, the part of v across u, their
// cross product (columns). u and v must not be parallel.
Matrix3d pair_frame(const Vector3d& u, const Vector3d& v) {
  Matrix3d frame;
  frame.col(0) = u.normalized();
  frame.col(1) = (v - v.dot(frame.col(0)) * frame.col(0)).normalized();
  frame.col(2) = frame.col(0).cross(frame.col(1));
  return frame;
}

void check_factor(const char* what, const char* segment, double factor, double patient_mm,
                  double atlas_mm, const ScalingOptions& options) {
  if (!(factor >= options.min_length_factor && factor <= options.max_length_factor)) {
    std::ostringstream message;
    message << what << ": the " << segment << " length factor " << factor << " (landmark distance "
            << patient_mm << " mm, in the atlas " << atlas_mm
            << " mm) is outside the plausible range [" << options.min_length_factor << ", "
            << options.max_length_factor
            << "]: check the landmark placement (names swapped? wrong units?)";
    throw InvalidInputError(message.str());
  }
}

// Solves the three-landmark shape (see the header) by Newton's method.
Shape solve_shape(const Skeleton& skeleton, const Targets& targets, const ScalingOptions& options,
                  const char* what) {
  const Vector3d h0 = skeleton.head->position;
  const Vector3d p0 = skeleton.patella->position;
  const Vector3d a0 = skeleton.ankle->position;
  const Vector3d& ankle = *targets.ankle;
  const double d1 = (targets.patella - targets.head).norm();
  const double d2 = (ankle - targets.patella).norm();
  // The patient's knee angle, unsigned: R may turn the triangle either way up.
  const double phi =
      std::atan2((targets.patella - targets.head).cross(ankle - targets.patella).norm(),
                 (targets.patella - targets.head).dot(ankle - targets.patella));
  Shape shape;
  const Vector3d normal = (p0 - h0).cross(a0 - p0);
  if (normal.norm() < 1e-9 * (p0 - h0).norm() * (a0 - p0).norm()) {
    throw InvalidInputError(std::string(what) + ": the atlas landmarks '" +
                            std::string(kFemoralHead) + "', '" + std::string(kPatella) + "' and '" +
                            std::string(kAnkle) +
                            "' are collinear: the knee rotation axis is undefined");
  }
  shape.knee_axis = normal.normalized();
  shape.femur_length = d1 / (p0 - h0).norm();
  shape.tibia_length = d2 / (a0 - p0).norm();
  shape.knee_angle_rad = phi - signed_angle(p0 - h0, a0 - p0, shape.knee_axis);
  const auto residual = [&](const Shape& trial) {
    const BoneMaps maps = shape_maps(skeleton, trial);
    const Vector3d u = mapped(maps, *skeleton.patella) - mapped(maps, *skeleton.head);
    const Vector3d v = mapped(maps, *skeleton.ankle) - mapped(maps, *skeleton.patella);
    // The angle in mm (times d2), so that one tolerance serves all three.
    return Vector3d(u.norm() - d1, v.norm() - d2, (signed_angle(u, v, trial.knee_axis) - phi) * d2);
  };
  const auto with = [&](const Eigen::Vector3d& x) {
    Shape trial = shape;
    trial.femur_length = x(0);
    trial.tibia_length = x(1);
    trial.knee_angle_rad = x(2);
    return trial;
  };
  Vector3d x(shape.femur_length, shape.tibia_length, shape.knee_angle_rad);
  Vector3d r = residual(shape);
  int iteration = 0;
  for (; iteration < options.max_iterations && r.cwiseAbs().maxCoeff() > options.tolerance_mm;
       ++iteration) {
    Matrix3d jacobian;
    for (int k = 0; k < 3; ++k) {
      // Central differences; the residuals are smooth in all three.
      constexpr double kStep = 1e-6;
      Vector3d plus = x;
      Vector3d minus = x;
      plus(k) += kStep;
      minus(k) -= kStep;
      jacobian.col(k) = (residual(with(plus)) - residual(with(minus))) / (2 * kStep);
    }
    const Eigen::FullPivLU<Matrix3d> lu(jacobian);
    if (!lu.isInvertible()) break;
    x -= lu.solve(r);
    if (!x.allFinite() || x(0) <= 0 || x(1) <= 0) break;
    r = residual(with(x));
  }
  if (!x.allFinite() || !r.allFinite() || r.cwiseAbs().maxCoeff() > options.tolerance_mm) {
    std::ostringstream message;
    message << what << ": no leg of the anatomical model reaches the three landmarks (after "
            << iteration << " Newton iterations: |P-H| off by " << r(0) << " mm, |A-P| by " << r(1)
            << " mm, knee angle by " << r(2) / d2
            << " rad); check the landmark placement or use two landmarks";
    throw SolverError(message.str());
  }
  return with(x);
}

// Maps every bone by G(x) = R x + t after its own map.
BoneMaps placed(const BoneMaps& maps, const Matrix3d& rotation, const Vector3d& translation) {
  Affine3d global = Affine3d::Identity();
  global.linear() = rotation;
  global.translation() = translation;
  BoneMaps result;
  for (const auto& [bone, map] : maps) result[bone] = global * map;
  return result;
}

ScalingEstimate finish(const atlas::Atlas& atlas, const Skeleton& skeleton,
                       const landmarks::LandmarkSet& landmarks, const Targets& targets,
                       BoneMaps maps, const std::map<std::string, double>& factors, double stature,
                       const ScalingOptions& options) {
  ScalingEstimate estimate;
  estimate.stature_scale = stature;
  atlas::PatientFactors& patient = estimate.deformation.factors;
  patient.seed = 0;
  patient.stature_scale = stature;
  patient.height_mm = stature * options.atlas_height_mm;
  for (const atlas::Bone& bone : atlas.bones) {
    const double factor = factors.contains(bone.name) ? factors.at(bone.name) : stature;
    estimate.segment_length_factor[bone.name] = factor;
    patient.length[bone.name] = factor / stature;
    patient.width[bone.name] = 1.0;
  }
  estimate.landmark_residual_mm[std::string(kFemoralHead)] =
      (mapped(maps, *skeleton.head) - targets.head).norm();
  estimate.landmark_residual_mm[std::string(kPatella)] =
      (mapped(maps, *skeleton.patella) - targets.patella).norm();
  if (targets.ankle) {
    estimate.landmark_residual_mm[std::string(kAnkle)] =
        (mapped(maps, *skeleton.ankle) - *targets.ankle).norm();
  }
  estimate.deformation.bone_maps = std::move(maps);
  if (landmarks.frame != "patient") {
    estimate.notes.push_back("the landmarks are in frame '" + landmarks.frame +
                             "', not 'patient': the maps carry the atlas into that frame");
  }
  return estimate;
}

}  // namespace

ScalingEstimate estimate_anatomical_scaling(const atlas::Atlas& atlas,
                                            const landmarks::LandmarkSet& landmarks,
                                            const ScalingOptions& options) {
  constexpr const char* kWhat = "anatomical scaling";
  const Targets targets = read_targets(landmarks, options, kWhat);
  const Skeleton skeleton = read_skeleton(atlas, targets.ankle.has_value(), kWhat);
  const Vector3d h0 = skeleton.head->position;
  const Vector3d p0 = skeleton.patella->position;
  Shape shape;
  if (targets.ankle) {
    shape = solve_shape(skeleton, targets, options, kWhat);
  } else {
    shape.femur_length = (targets.patella - targets.head).norm() / (p0 - h0).norm();
    shape.tibia_length = shape.femur_length;
  }
  check_factor(kWhat, "femur", shape.femur_length, (targets.patella - targets.head).norm(),
               (p0 - h0).norm(), options);
  if (targets.ankle) {
    check_factor(kWhat, "tibia", shape.tibia_length, (*targets.ankle - targets.patella).norm(),
                 (skeleton.ankle->position - p0).norm(), options);
  }
  const BoneMaps maps = shape_maps(skeleton, shape);
  const Vector3d head = mapped(maps, *skeleton.head);
  const Vector3d u = mapped(maps, *skeleton.patella) - head;
  Matrix3d rotation;
  if (targets.ankle) {
    const Vector3d v = mapped(maps, *skeleton.ankle) - mapped(maps, *skeleton.patella);
    rotation = pair_frame(targets.patella - targets.head, *targets.ankle - targets.patella) *
               pair_frame(u, v).transpose();
  } else {
    rotation = Eigen::Quaterniond::FromTwoVectors(u, targets.patella - targets.head).matrix();
  }
  ScalingEstimate estimate = finish(
      atlas, skeleton, landmarks, targets, placed(maps, rotation, targets.head - rotation * head),
      {{skeleton.femur, shape.femur_length}, {skeleton.tibia, shape.tibia_length}}, shape.stature(),
      options);
  // Welded bones report their segment's factor.
  for (auto& [bone, factor] : estimate.segment_length_factor) {
    const std::string segment = segment_of(skeleton, bone);
    if (segment == skeleton.femur) factor = shape.femur_length;
    if (segment == skeleton.tibia) factor = shape.tibia_length;
  }
  for (auto& [bone, length] : estimate.deformation.factors.length) {
    length = estimate.segment_length_factor.at(bone) / shape.stature();
  }
  estimate.knee_rotation_deg = shape.knee_angle_rad * 180.0 / std::numbers::pi;
  if (!targets.ankle) {
    estimate.notes.emplace_back(
        "two landmarks fix one length: every bone scales by |P - H| / |P0 - H0| (the tibia "
        "assumed to scale like the femur) and the leg's rotation about the H-P line is the "
        "atlas's; this is the uniform baseline");
  }
  return estimate;
}

ScalingEstimate estimate_uniform_scaling(const atlas::Atlas& atlas,
                                         const landmarks::LandmarkSet& landmarks,
                                         const ScalingOptions& options) {
  constexpr const char* kWhat = "uniform scaling";
  const Targets targets = read_targets(landmarks, options, kWhat);
  const Skeleton skeleton = read_skeleton(atlas, targets.ankle.has_value(), kWhat);
  const Vector3d h0 = skeleton.head->position;
  const Vector3d p0 = skeleton.patella->position;
  Affine3d similarity = Affine3d::Identity();
  double scale = 1.0;
  if (targets.ankle) {
    Eigen::MatrixX3d source(3, 3);
    Eigen::MatrixX3d target(3, 3);
    source << h0.transpose(), p0.transpose(), skeleton.ankle->position.transpose();
    target << targets.head.transpose(), targets.patella.transpose(), targets.ankle->transpose();
    fit::RigidFitOptions fit_options;
    fit_options.model = fit::TransformModel::kSimilarity;
    try {
      const fit::RigidFitResult fit = fit::rigid_fit(source, target, fit_options);
      similarity = fit.transform;
      scale = fit.scale;
    } catch (const InvalidInputError& error) {
      throw InvalidInputError(std::string(kWhat) + ": " + error.what());
    }
  } else {
    scale = (targets.patella - targets.head).norm() / (p0 - h0).norm();
    similarity.linear() =
        scale *
        Eigen::Quaterniond::FromTwoVectors(p0 - h0, targets.patella - targets.head).matrix();
    similarity.translation() = targets.head - similarity.linear() * h0;
  }
  check_factor(kWhat, "uniform", scale, (targets.patella - targets.head).norm(), (p0 - h0).norm(),
               options);
  BoneMaps maps;
  for (const atlas::Bone& bone : atlas.bones) maps[bone.name] = similarity;
  return finish(atlas, skeleton, landmarks, targets, std::move(maps), {}, scale, options);
}

}  // namespace mmm::scaling

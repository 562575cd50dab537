#pragma once
// Muscle wrapping over a fused motion, energy-minimisation pathway: per
// frame, every muscle's action lines are re-routed on the moving skeleton
// (action_line_path.h) and its surface is deformed around them keeping its
// volume and staying out of the bones (muscle_binding.h, volume_deformer.h,
// bone_contacts.h).
//
// Per muscle, once: the surface at the wrapping resolution (the full mesh
// decimated to `target_faces`), the binding to its rest action lines and
// attachment bones, the factored energy, the rest distances to the bones.
// Per frame, in order: the skeleton at the frame's coordinates, the line
// paths and moment arms, the targets, the volume-constrained solve with the
// contacts found inside it. Contacts of the previous frame start the next
// one, carried by their bones; `intermediate_poses` > 0 solves at that many
// coordinate vectors between the previous frame and this one first (for the
// first frame, `first_frame_intermediate_poses` from the rest pose) (the interpolated variant, for
// large motions: a vertex is pushed out of a bone on the side it entered). Muscles are independent
// and run on `threads` threads.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/mesh/mesh.h"
#include "core/motion/motion_fusion.h"
#include "core/wrapping/action_line_path.h"
#include "core/wrapping/bone_contacts.h"
#include "core/wrapping/line_router.h"
#include "core/wrapping/muscle_binding.h"
#include "core/wrapping/muscle_hulls.h"
#include "core/wrapping/muscle_penetration.h"
#include "core/wrapping/volume_deformer.h"

namespace mmm::wrapping {

struct MuscleWrappingOptions {
  Eigen::Index target_faces = 10000;  // wrapping resolution; 0: the full mesh
  bool bone_contacts = true;          // impenetrability with the bones
  // Measure how far the wrapped muscles run into each other, per frame
  // (muscle_penetration.h); a metric only: nothing keeps them apart. Costs
  // about as much again as the wrapping (every pair of touching muscles,
  // every frame).
  bool muscle_penetration = false;
  // Impenetrability between muscles (muscle_separation.h,
  // muscle_penetration.h). The overlaps the atlas has at rest are resolved
  // first, once (the separated surfaces become the rest); then, per pose,
  // every muscle is solved with the bones alone, and again in
  // `muscle_contact_rounds` rounds with the shared contacts of the previous
  // solve pinned (two overlapping muscles meet between their surfaces) and new
  // entries into the others found inside the iterations. The muscles go pose
  // by pose together (frame-major). Implies the muscle_penetration metric.
  // Before the contacts, touching muscles share their motion across their
  // interface (muscle_interfaces.h): the vertices within
  // `muscle_interface_reach_mm` of another muscle at rest blend its motion
  // into their targets (0: each muscle follows its own lines alone).
  bool muscle_contacts = false;
  MuscleContactOptions muscle_contact;
  int muscle_contact_rounds = 2;  // >= 1
  // Then, while a muscle is still inside another, up to
  // `muscle_contact_settling_rounds` more in which only such muscles are
  // solved again, each pinned onto the surface it entered as firmly as to a
  // bone (deformer.contact_weight) while that surface holds still: the shares
  // were taken in the rounds before; what is left is settled one-sided.
  // Settling can overshoot, so each pose keeps the surfaces whose deepest
  // entry into another muscle was the shallowest (measured before every
  // settling round and after the last). With settling rounds, a pin that
  // would hold a vertex inside a bone is dropped, in every round.
  int muscle_contact_settling_rounds = 0;  // >= 0
  // Instead of those rounds, the muscles that run into each other are solved
  // together (joint_deformer.h): each vertex found inside another muscle is
  // tied to that muscle's surface, both move in one solve, and new entries
  // are looked for on the current surfaces, for up to `joint_rounds` solves.
  bool joint_muscle_contacts = false;
  int joint_rounds = 10;                    // >= 1
  double muscle_interface_reach_mm = 20.0;  // >= 0
  // Separation at rest: firmer pins than in motion, more rounds.
  double separation_weight = 1e3;
  int separation_rounds = 12;
  int intermediate_poses = 0;  // >= 0, between consecutive frames
  // Between the rest pose and the first frame, usually far apart: a vertex
  // driven deep into a bone in one step is projected out across a crowd of
  // others (folds); in small steps it is pushed out where it enters.
  int first_frame_intermediate_poses = 8;  // >= 0
  std::vector<std::string> muscles;        // empty: every muscle of the atlas
  // Coarse to fine (section 3.4.2): per pose the muscle's progressive hull
  // (hull_faces) is solved first, with its own volume and bone contacts;
  // the surface then starts from where the hull carries it (hull_embedding.h),
  // blended into its attachment bones' motion, and is solved with its own
  // contacts and exact volume. false: the surface is solved directly.
  bool coarse_to_fine = true;
  Eigen::Index hull_faces = 1000;
  // Stored hulls (muscle_hulls.h): one whose source hash matches the
  // wrapping surface and whose face count matches hull_faces is reused,
  // else the hull is built.
  std::vector<MuscleHull> hulls;
  std::vector<std::string> moment_arm_coordinates = {
      "hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r"};
  int threads = 0;  // 0: the hardware's
  DeformerOptions deformer;
  BindingOptions binding;
  ContactOptions contacts;
  // Action-line paths: obstacle set (default) or global (bone meshes).
  RouterOptions routing;
};

struct MuscleFrameMetrics {
  double volume_error_percent = 0.0;
  double max_depth_mm = 0.0;  // into any bone
  int vertices_inside = 0;    // inside a bone at any depth
  int vertices_deeper = 0;    // deeper than the contact tolerance
  std::string deepest_bone;
  // With options.muscle_penetration: the deepest vertex inside another
  // muscle beyond its depth there at rest, the vertices deeper than that by
  // the contact tolerance, and that muscle (index into
  // MuscleWrapping::muscles; -1: none).
  double muscle_depth_mm = 0.0;
  int muscle_vertices_deeper = 0;
  int deepest_muscle = -1;
  double smoothness_change_percent = 0.0;  // bending energy sum |L x|^2 vs rest
  int contacts = 0;
  int path_contacts = 0;  // global paths: segments resting on a bone
  int hull_contacts = 0;  // coarse to fine: contacts of the hull's solve
  int contact_rounds = 0;
  int volume_iterations = 0;
  bool converged = true;
  double seconds = 0.0;  // wall time of this muscle-frame (paths, targets, solve)
};

struct WrappedLine {
  std::string name;
  std::vector<std::vector<Eigen::Vector3d>> paths;  // per frame (mm)
  std::vector<double> lengths_mm;                   // per frame
  Eigen::MatrixXd moment_arms_mm;  // frames by moment-arm coordinates (NaN: absent)
};

struct WrappedMuscle {
  std::string name;
  mesh::IndexedMesh rest;                   // at the wrapping resolution (atlas frame)
  std::vector<Eigen::MatrixX3f> positions;  // per frame (mm)
  std::vector<MuscleFrameMetrics> frames;
  std::vector<WrappedLine> lines;
  double setup_seconds = 0.0;  // decimation, hull, binding, factorisation, rest distances
  // Coarse to fine: the hull's faces (0: solved directly), whether a stored
  // hull was reused, its containment check and volume, its build time (0
  // when reused) and the largest distance of the surface inside it.
  Eigen::Index hull_faces = 0;
  bool hull_reused = false;
  int hull_vertices_outside = 0;
  double hull_max_outside_mm = 0.0;
  double hull_volume_mm3 = 0.0;
  double hull_build_seconds = 0.0;
  double hull_max_offset_mm = 0.0;
  double rest_volume_mm3 = 0.0;
  PenetrationMetrics rest_penetration;  // of the rest surface in the rest pose
  // With muscle contacts (muscle_separation.h): the deepest vertex inside
  // another muscle in the atlas at rest, after separating, and the largest
  // move of the separation (mm); `rest` is the separated surface.
  double rest_overlap_before_mm = 0.0;
  double rest_overlap_after_mm = 0.0;
  double separation_move_mm = 0.0;
  // With muscle contacts: the vertices that share a neighbour's motion
  // (muscle_interfaces.h).
  int interface_vertices = 0;
};

struct MuscleWrapping {
  std::vector<WrappedMuscle> muscles;  // in atlas order
  std::vector<std::string> moment_arm_coordinates;
  Eigen::VectorXd times;                                   // s, per frame
  std::vector<std::string> bone_names;                     // posed bones, as in bone_poses
  std::vector<std::vector<Eigen::Isometry3d>> bone_poses;  // [frame][bone], rest -> frame
  double seconds = 0.0;                                    // wall time of the whole wrapping
  int threads = 1;
  bool muscle_penetration = false;          // measured (options.muscle_penetration)
  double muscle_penetration_seconds = 0.0;  // of that measurement (included in seconds)
  double separation_seconds = 0.0;          // muscle contacts: separating at rest (included)
  int separation_rounds = 0;
};

// atlas + its folder (meshes), a motion fused on a skeleton of this atlas
// (its coordinates are matched by name; missing ones keep their rest value).
// Throws InvalidInputError for an unknown muscle, a muscle without action
// lines, a motion without frames or none of the atlas's coordinates.
MuscleWrapping wrap_muscles(const atlas::Atlas& atlas, const std::filesystem::path& atlas_dir,
                            const motion::FusedMotion& motion,
                            const MuscleWrappingOptions& options = {});

}  // namespace mmm::wrapping

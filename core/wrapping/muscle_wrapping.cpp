#include "core/wrapping/muscle_wrapping.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/laplacian.h"
#include "core/motion/skeleton.h"
#include "core/parallel_for.h"
#include "core/wrapping/hull_embedding.h"
#include "core/wrapping/joint_deformer.h"
#include "core/wrapping/muscle_interfaces.h"
#include "core/wrapping/muscle_penetration.h"
#include "core/wrapping/muscle_separation.h"
#include "core/wrapping/posed_skeleton.h"

namespace mmm::wrapping {
namespace {

using Clock = std::chrono::steady_clock;
using Eigen::Isometry3d;
using Eigen::MatrixX3d;
using Eigen::VectorXd;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double bending(const Eigen::SparseMatrix<double>& laplacian, const MatrixX3d& x) {
  return (laplacian * x).squaredNorm();
}

// Contacts of the previous solve carried to new bone poses.
std::vector<Contact> carried(const std::vector<Contact>& contacts,
                             const std::vector<Isometry3d>& from,
                             const std::vector<Isometry3d>& to) {
  std::vector<Contact> result;
  result.reserve(contacts.size());
  for (Contact contact : contacts) {
    if (is_muscle_obstacle(contact.obstacle)) continue;  // found again against the new surfaces
    if (contact.obstacle >= 0) {
      const auto b = static_cast<std::size_t>(contact.obstacle);
      contact.target = to[b] * (from[b].inverse() * contact.target);
    }
    result.push_back(contact);
  }
  return result;
}

// One resolution of a muscle (its wrapping surface, or its hull): binding,
// factored energy, bone contacts, and the contacts carried between solves.
struct Level {
  std::unique_ptr<BoneContacts> contacts;
  std::unique_ptr<MuscleBinding> binding;
  std::unique_ptr<VolumeDeformer> deformer;
  std::vector<Contact> carried;
};

Level make_level(const mesh::IndexedMesh& surface, const std::vector<LinePath>& rest_lines,
                 const std::set<int>& attachment_bones, const PosedBones& bones,
                 const MuscleWrappingOptions& options) {
  Level level;
  level.contacts = std::make_unique<BoneContacts>(surface.V, bones.surfaces, options.contacts);
  std::vector<AttachmentBone> attachments;
  attachments.reserve(attachment_bones.size());
  for (const int b : attachment_bones) {
    attachments.push_back(
        {b, level.contacts->rest_distance(static_cast<std::size_t>(b)).cwiseMax(0.0)});
  }
  level.binding = std::make_unique<MuscleBinding>(surface.V, surface.F, rest_lines,
                                                  std::move(attachments), options.binding);
  level.deformer = std::make_unique<VolumeDeformer>(surface, options.deformer);
  return level;
}

// Where the hull carries the surface, except near the attachments, which
// follow their bones as the binding has them.
MuscleBinding::Targets blend_with_hull(const MuscleBinding::Targets& own,
                                       const HullEmbedding::Transfer& from_hull,
                                       const Eigen::VectorXd& bone_blend) {
  MuscleBinding::Targets targets;
  targets.positions.resize(own.positions.rows(), 3);
  targets.rotations.resize(own.rotations.size());
  for (Eigen::Index i = 0; i < own.positions.rows(); ++i) {
    const double beta = bone_blend[i];
    const auto k = static_cast<std::size_t>(i);
    targets.positions.row(i) =
        beta * own.positions.row(i) + (1.0 - beta) * from_hull.positions.row(i);
    if (beta <= 0.0) {
      targets.rotations[k] = from_hull.rotations[k];
    } else {
      const Eigen::Quaterniond hull_turn(from_hull.rotations[k]);
      const Eigen::Quaterniond own_turn(own.rotations[k]);
      targets.rotations[k] = hull_turn.slerp(beta, own_turn).toRotationMatrix();
    }
  }
  return targets;
}

class MuscleWrapper {
 public:
  MuscleWrapper(const atlas::Atlas& atlas, const atlas::Muscle& muscle,
                const std::filesystem::path& dir, const motion::Skeleton& skeleton,
                const PosedBones& bones, const VectorXd& rest_q,
                const MuscleWrappingOptions& options,
                const mesh::IndexedMesh* surface_at_rest = nullptr)
      : muscle_(muscle), skeleton_(skeleton), bones_(bones), options_(options) {
    const Clock::time_point start = Clock::now();
    if (muscle.action_lines.empty()) {
      throw InvalidInputError("muscle wrapping: muscle '" + muscle.name + "' has no action line");
    }
    result_.name = muscle.name;
    const mesh::IndexedMesh surface = surface_at_rest != nullptr
                                          ? *surface_at_rest
                                          : wrapping_surface(muscle, dir, options.target_faces);
    result_.rest = surface;
    laplacian_ = mesh::cotangent_laplacian(surface.V, surface.F);
    rest_bending_ = bending(laplacian_, surface.V);

    motion::SkeletonPose pose(skeleton);
    pose.set(rest_q);
    rest_poses_ = bone_poses(pose, bones);
    // The skeleton at rest is the atlas moved rigidly (every bone by the
    // root's rest pose, skeleton_from_atlas): the rest paths go back to the
    // atlas frame, where the surface is.
    std::vector<RoutingBone> routing_bones;
    if (options.routing.method == PathMethod::kGlobal) {
      for (std::size_t b = 0; b < bones.names.size(); ++b)
        routing_bones.push_back({bones.surfaces[b].surface.get(), bones.bodies[b]});
    }
    for (const atlas::ActionLine& line : muscle.action_lines)
      routers_.emplace_back(atlas, muscle, line, skeleton, routing_bones, options.routing);
    std::vector<LinePath> rest_lines = lines_at(rest_q, -1);
    const Isometry3d to_atlas = rest_poses_.front().inverse();
    for (const Isometry3d& bone_pose : rest_poses_) {
      if (!(bone_pose.matrix() - rest_poses_.front().matrix()).isZero(1e-6)) {
        throw InvalidInputError(
            "muscle wrapping: the atlas skeleton at rest does not keep every bone where the "
            "atlas has it (bone '" +
            bones.names[static_cast<std::size_t>(&bone_pose - rest_poses_.data())] +
            "'); hint: check the atlas's joints (mmm atlas check)");
      }
    }
    for (LinePath& line : rest_lines) {
      for (Eigen::Vector3d& point : line.points) point = to_atlas * point;
    }
    for (const atlas::ActionLine& line : muscle.action_lines)
      result_.lines.push_back({line.name, {}, {}, {}});

    std::set<int> attachment_bones;
    for (const auto* areas : {&muscle.origins, &muscle.insertions}) {
      for (const atlas::AttachmentArea& area : *areas) {
        if (const auto found = bones.index.find(area.bone); found != bones.index.end()) {
          attachment_bones.insert(found->second);
        }
      }
    }
    for (const LinePath& line : rest_lines) {
      attachment_bones.insert(line.origin_pose_index);
      attachment_bones.insert(line.insertion_pose_index);
    }
    fine_ = make_level(surface, rest_lines, attachment_bones, bones, options);
    if (options.coarse_to_fine) {
      const std::string source_hash = mesh_hash(surface);
      const MuscleHull* stored =
          find_hull(options.hulls, muscle.name, source_hash, options.hull_faces);
      const MuscleHull hull =
          stored != nullptr ? *stored : build_muscle_hull(muscle.name, surface, options.hull_faces);
      result_.hull_reused = stored != nullptr;
      result_.hull_build_seconds = stored != nullptr ? 0.0 : hull.seconds;
      result_.hull_faces = hull.hull.F.rows();
      result_.hull_vertices_outside = hull.report.vertices_outside;
      result_.hull_max_outside_mm = hull.report.max_outside_mm;
      coarse_ = make_level(hull.hull, rest_lines, attachment_bones, bones, options);
      result_.hull_volume_mm3 = coarse_->deformer->rest_volume();
      embedding_ = std::make_unique<HullEmbedding>(hull.hull, surface.V);
      result_.hull_max_offset_mm = embedding_->max_offset();
    }
    result_.rest_volume_mm3 = fine_.deformer->rest_volume();
    result_.rest_penetration = fine_.contacts->measure(
        surface.V, std::vector<Isometry3d>(bones.names.size(), Isometry3d::Identity()));
    previous_q_ = rest_q;
    previous_poses_ = rest_poses_;
    result_.setup_seconds = seconds_since(start);
  }

  // Poses solved for the next frame (its intermediate ones, then its own).
  [[nodiscard]] int stages() const {
    return (result_.frames.empty() ? options_.first_frame_intermediate_poses
                                   : options_.intermediate_poses) +
           1;
  }
  [[nodiscard]] VectorXd stage_coordinates(const VectorXd& q, int stage) const {
    const double t = static_cast<double>(stage) / stages();
    return (1.0 - t) * previous_q_ + t * q;
  }

  // A frame, without contacts between muscles.
  void frame(const VectorXd& q) {
    for (int stage = 1; stage <= stages(); ++stage) {
      prepare_stage(stage_coordinates(q, stage), stage == stages());
      solve_stage(nullptr);
    }
    end_frame(q);
  }

  // The pose's bones, action lines (recorded when it is the frame's own,
  // `last`) and targets; coarse to fine: the hull's solve.
  void prepare_stage(const VectorXd& q_stage, bool last) {
    const Clock::time_point start = Clock::now();
    motion::SkeletonPose pose(skeleton_);
    pose.set(q_stage);
    poses_ = bone_poses(pose, bones_);
    const std::vector<LinePath> lines =
        lines_at(q_stage, last ? static_cast<int>(result_.frames.size()) : -1);
    targets_ = fine_.binding->targets(lines, poses_);
    hull_solved_ = DeformResult{};
    if (coarse_) {
      const MuscleBinding::Targets hull_targets = coarse_->binding->targets(lines, poses_);
      hull_solved_ = solve(*coarse_, hull_targets, poses_);
      targets_ = blend_with_hull(targets_, embedding_->transfer(hull_solved_.x),
                                 fine_.binding->bone_blend());
    }
    frame_seconds_ += seconds_since(start);
  }

  // The surface's solve in the prepared pose; `others`: every muscle's
  // surface in this pose, to stay out of (nullptr: bones only).
  void solve_stage(const MuscleSurfaces* others = nullptr,
                   const std::vector<Contact>* pins = nullptr,
                   const MuscleClearance* clearance = nullptr) {
    const Clock::time_point start = Clock::now();
    solved_ = solve(fine_, targets_, poses_, others, pins, clearance);
    previous_poses_ = poses_;
    frame_seconds_ += seconds_since(start);
  }

  void end_frame(const VectorXd& q) {
    const Clock::time_point start = Clock::now();
    previous_q_ = q;
    MuscleFrameMetrics metrics;
    metrics.volume_error_percent = 100.0 * solved_.volume_error;
    const PenetrationMetrics penetration = fine_.contacts->measure(solved_.x, poses_);
    metrics.max_depth_mm = penetration.max_depth_mm;
    metrics.vertices_inside = penetration.vertices_inside;
    metrics.vertices_deeper = penetration.vertices_deeper;
    metrics.deepest_bone = penetration.deepest_bone;
    metrics.smoothness_change_percent =
        100.0 * (bending(laplacian_, solved_.x) / rest_bending_ - 1.0);
    metrics.contacts = static_cast<int>(solved_.contacts.size());
    metrics.hull_contacts = static_cast<int>(hull_solved_.contacts.size());
    metrics.path_contacts = path_contacts_;
    metrics.contact_rounds = solved_.contact_rounds;
    metrics.volume_iterations = solved_.volume_iterations;
    metrics.converged = solved_.converged && hull_solved_.converged;
    result_.positions.emplace_back(solved_.x.cast<float>());
    metrics.seconds = frame_seconds_ + seconds_since(start);
    frame_seconds_ = 0.0;
    result_.frames.push_back(metrics);
  }

  // This muscle's part of a joint solve of touching muscles, in the
  // prepared pose, from its last solve (joint_deformer.h).
  [[nodiscard]] JointBody joint_body() {
    JointBody body;
    body.deformer = fine_.deformer.get();
    body.right_hand_side = fine_.deformer->right_hand_side(targets_.positions, targets_.rotations);
    body.start = solved_.x;
    body.contacts = solved_.contacts;
    if (options_.bone_contacts) {
      body.query = [this](const MatrixX3d& x, const std::vector<char>& active) {
        return fine_.contacts->find(x, poses_, active);
      };
    }
    return body;
  }
  // Its result, and its share of the joint solve's time.
  void take_joint_solve(DeformResult solved, double seconds) {
    solved_ = std::move(solved);
    fine_.carried = solved_.contacts;
    frame_seconds_ += seconds;
  }

  // The last solve, and a way back to it (settling rounds keep the pose's
  // best surfaces).
  [[nodiscard]] const DeformResult& last_solve() const { return solved_; }
  void restore_solve(const DeformResult& solved) {
    solved_ = solved;
    fine_.carried = solved_.contacts;
  }

  // The surface after the last solve (world, mm).
  [[nodiscard]] const MatrixX3d& current() const { return solved_.x; }
  [[nodiscard]] const Eigen::MatrixX3i& faces() const { return result_.rest.F; }
  [[nodiscard]] const MatrixX3d& rest_vertices() const { return result_.rest.V; }
  // The prepared pose's targets, and the same blended with the other
  // muscles' across their interfaces (muscle_interfaces.h): all[n] is muscle
  // n's own in this pose.
  [[nodiscard]] const MuscleBinding::Targets& targets() const { return targets_; }
  void blend_targets(const std::vector<InterfaceLink>& links,
                     const std::vector<const MuscleBinding::Targets*>& all) {
    const Clock::time_point start = Clock::now();
    targets_ = blend_interfaces(targets_, links, all, fine_.binding->bone_blend());
    frame_seconds_ += seconds_since(start);
  }

  // Contacts between muscles: this muscle's index among the wrapped ones.
  void set_index(int index) { index_ = index; }
  void set_interface_vertices(int count) { result_.interface_vertices = count; }
  void set_separation(double overlap_before_mm, double overlap_after_mm, double max_move_mm) {
    result_.rest_overlap_before_mm = overlap_before_mm;
    result_.rest_overlap_after_mm = overlap_after_mm;
    result_.separation_move_mm = max_move_mm;
  }

  WrappedMuscle take() { return std::move(result_); }

 private:
  // The action lines in the pose; with frame >= 0 their paths, lengths and
  // moment arms are recorded for that frame.
  std::vector<LinePath> lines_at(const VectorXd& q, int frame) {
    std::vector<LinePath> lines;
    path_contacts_ = 0;
    for (std::size_t l = 0; l < muscle_.action_lines.size(); ++l) {
      const atlas::ActionLine& line = muscle_.action_lines[l];
      LineRouter& router = routers_[l];
      const ActionLinePath path = router.route(q);
      path_contacts_ += router.last_contacts();
      LinePath posed;
      posed.points = path.points;
      posed.origin_pose_index =
          bone_index(bones_, line.points.front().bone, "the origin of " + line.name);
      posed.insertion_pose_index =
          bone_index(bones_, line.points.back().bone, "the insertion of " + line.name);
      posed.point_names = path.point_names;
      for (const std::string& bone : path.point_bones) {
        posed.point_pose_indices.push_back(
            bone.empty() ? posed.point_pose_indices.back()
                         : bone_index(bones_, bone, "a path point of " + line.name));
      }
      lines.push_back(std::move(posed));
      if (frame < 0) continue;
      WrappedLine& record = result_.lines[l];
      record.paths.push_back(path.points);
      record.lengths_mm.push_back(path.length);
      const auto arms = static_cast<Eigen::Index>(options_.moment_arm_coordinates.size());
      record.moment_arms_mm.conservativeResize(frame + 1, arms);
      for (Eigen::Index c = 0; c < arms; ++c) {
        const auto coordinate = skeleton_.coordinate_index(
            options_.moment_arm_coordinates[static_cast<std::size_t>(c)]);
        record.moment_arms_mm(frame, c) = coordinate ? router.moment_arm(q, *coordinate)
                                                     : std::numeric_limits<double>::quiet_NaN();
      }
    }
    return lines;
  }

  // One volume-constrained solve of a level in this stage's bone poses, its
  // contacts carried from the previous stage and found inside the solve.
  // With muscle contacts: `pins` (the shared contacts of this muscle, pinned
  // from the start) and `others` (the surfaces they were found on, where new
  // entries are looked for).
  DeformResult solve(Level& level, const MuscleBinding::Targets& targets,
                     const std::vector<Isometry3d>& poses, const MuscleSurfaces* others = nullptr,
                     const std::vector<Contact>* pins = nullptr,
                     const MuscleClearance* clearance = nullptr) {
    std::vector<Contact> contacts = carried(level.carried, previous_poses_, poses);
    if (!options_.bone_contacts) {
      contacts.erase(std::remove_if(contacts.begin(), contacts.end(),
                                    [](const Contact& c) { return c.obstacle >= 0; }),
                     contacts.end());
    }
    if (pins != nullptr) {
      std::vector<char> taken(static_cast<std::size_t>(level.deformer->rest().V.rows()), 0);
      for (const Contact& contact : contacts) taken[static_cast<std::size_t>(contact.vertex)] = 1;
      const std::vector<char> in_bone = pins_into_bone(level, *pins, poses);
      for (const Contact& pin : *pins) {
        const auto v = static_cast<std::size_t>(pin.vertex);
        if (taken[v] == 0 && in_bone[v] == 0) contacts.push_back(pin);
      }
    }
    ContactQuery query;
    if (options_.bone_contacts || others != nullptr) {
      query = [&](const MatrixX3d& x, const std::vector<char>& active) {
        std::vector<Contact> found;
        if (options_.bone_contacts) found = level.contacts->find(x, poses, active);
        if (others != nullptr) {
          std::vector<char> taken = active;
          for (const Contact& contact : found) taken[static_cast<std::size_t>(contact.vertex)] = 1;
          const std::vector<Contact> entries =
              muscle_entries(index_, x, taken, *others, options_.muscle_contact, clearance);
          found.insert(found.end(), entries.begin(), entries.end());
        }
        return found;
      };
    }
    DeformResult solved =
        level.deformer->solve(targets.positions, targets.rotations, std::move(contacts), query);
    level.carried = solved.contacts;
    return solved;
  }

  // Per vertex: 1 where a pin of another muscle would hold it inside a bone
  // (a muscle squeezed between a bone and another muscle gives way to the
  // muscle, never into the bone); only with settling rounds, whose firm pins
  // would otherwise press it in.
  std::vector<char> pins_into_bone(const Level& level, const std::vector<Contact>& pins,
                                   const std::vector<Isometry3d>& poses) const {
    std::vector<char> in_bone(static_cast<std::size_t>(level.deformer->rest().V.rows()), 0);
    if (!options_.bone_contacts || options_.muscle_contact_settling_rounds == 0 || pins.empty() ||
        solved_.x.rows() != static_cast<Eigen::Index>(in_bone.size()))
      return in_bone;
    MatrixX3d at_targets = solved_.x;
    std::vector<char> others(in_bone.size(), 1);
    for (const Contact& pin : pins) {
      at_targets.row(pin.vertex) = pin.target.transpose();
      others[static_cast<std::size_t>(pin.vertex)] = 0;
    }
    for (const Contact& inside : level.contacts->find(at_targets, poses, others))
      in_bone[static_cast<std::size_t>(inside.vertex)] = 1;
    return in_bone;
  }

  const atlas::Muscle& muscle_;
  const motion::Skeleton& skeleton_;
  const PosedBones& bones_;
  const MuscleWrappingOptions& options_;
  WrappedMuscle result_;
  Eigen::SparseMatrix<double> laplacian_;
  double rest_bending_ = 1.0;
  std::vector<Isometry3d> rest_poses_;
  std::vector<Isometry3d> previous_poses_;
  VectorXd previous_q_;
  std::vector<Isometry3d> poses_;    // bones in the prepared pose
  MuscleBinding::Targets targets_;   // of the prepared pose
  DeformResult solved_;              // the surface's last solve
  DeformResult hull_solved_;         // the hull's last solve
  double frame_seconds_ = 0.0;       // of the current frame so far
  int index_ = -1;                   // among the wrapped muscles (muscle contacts)
  std::vector<LineRouter> routers_;  // per action line
  int path_contacts_ = 0;            // of the last lines_at
  Level fine_;
  std::optional<Level> coarse_;  // coarse to fine: the hull
  std::unique_ptr<HullEmbedding> embedding_;
};

}  // namespace

MuscleWrapping wrap_muscles(const atlas::Atlas& atlas, const std::filesystem::path& atlas_dir,
                            const motion::FusedMotion& motion,
                            const MuscleWrappingOptions& options) {
  const Clock::time_point start = Clock::now();
  if (motion.num_frames() == 0) throw InvalidInputError("muscle wrapping: the motion has no frame");
  if (options.intermediate_poses < 0)
    throw InvalidInputError("muscle wrapping: intermediate_poses must be >= 0");
  if (options.coarse_to_fine && options.hull_faces < 4)
    throw InvalidInputError("muscle wrapping: hull_faces must be >= 4 (a tetrahedron)");
  if (options.muscle_contacts) {
    const MuscleContactOptions& c = options.muscle_contact;
    if (!(c.share >= 0.0 && c.share <= 1.0) || !(c.weight > 0.0) || !std::isfinite(c.weight) ||
        !(c.reach_mm > 0.0) || !(c.tolerance_mm >= 0.0) || options.muscle_contact_rounds < 1 ||
        options.muscle_contact_settling_rounds < 0 || options.joint_rounds < 1 ||
        !(options.muscle_interface_reach_mm >= 0.0) ||
        !std::isfinite(options.muscle_interface_reach_mm) || options.separation_rounds < 1 ||
        !(options.separation_weight > 0.0) || !std::isfinite(options.separation_weight)) {
      throw InvalidInputError(
          "muscle wrapping: muscle contacts need a share in [0, 1], weights > 0, reach > 0, "
          "tolerance >= 0, an interface reach >= 0, at least one round "
          "(muscle_contact_rounds, joint_rounds, separation_rounds) and settling rounds >= 0");
    }
  }
  const std::vector<const atlas::Muscle*> muscles = selected_muscles(atlas, options.muscles);
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(atlas);
  const VectorXd rest_q = rest_coordinates(atlas, skeleton);
  const std::vector<VectorXd> frames = frame_coordinates(motion, skeleton, rest_q);
  const PosedBones bones = load_bones(atlas, atlas_dir, skeleton);

  MuscleWrapping result;
  result.times = motion.times;
  result.bone_names = bones.names;
  result.moment_arm_coordinates = options.moment_arm_coordinates;
  motion::SkeletonPose pose(skeleton);
  for (const VectorXd& q : frames) {
    pose.set(q);
    result.bone_poses.push_back(bone_poses(pose, bones));
  }

  const int hardware = machine_threads();
  const int threads = std::clamp(options.threads > 0 ? options.threads : hardware, 1,
                                 static_cast<int>(std::max<std::size_t>(1, muscles.size())));
  result.threads = threads;
  result.muscles.resize(muscles.size());
  if (!options.muscle_contacts) {
    // Muscles independent: each runs through the whole motion on its own.
    parallel_for(muscles.size(), threads, [&](std::size_t m) {
      MuscleWrapper wrapper(atlas, *muscles[m], atlas_dir, skeleton, bones, rest_q, options);
      for (const VectorXd& q : frames) wrapper.frame(q);
      result.muscles[m] = wrapper.take();
    });
  } else {
    // Pose by pose: every muscle solved with the bones, then again kept out
    // of the others' surfaces of that first solve (same pose, so the common
    // motion of the body cancels), each taking its share of an overlap.
    // Overlaps the atlas has at rest are resolved once, first.
    std::vector<mesh::IndexedMesh> surfaces(muscles.size());
    parallel_for(muscles.size(), threads, [&](std::size_t m) {
      surfaces[m] = wrapping_surface(*muscles[m], atlas_dir, options.target_faces);
    });
    SeparationOptions separation_options;
    separation_options.contact = options.muscle_contact;
    separation_options.contact.weight = options.separation_weight;
    separation_options.max_rounds = options.separation_rounds;
    separation_options.deformer = options.deformer;
    separation_options.bone_contacts = options.contacts;
    const MuscleSeparation separation = separate_muscles(
        surfaces, options.bone_contacts ? bones.surfaces : std::vector<PosableBone>{},
        separation_options, threads);
    result.separation_seconds = separation.seconds;
    result.separation_rounds = separation.rounds;
    std::vector<std::unique_ptr<MuscleWrapper>> wrappers(muscles.size());
    parallel_for(muscles.size(), threads, [&](std::size_t m) {
      const mesh::IndexedMesh separated{separation.positions[m], surfaces[m].F};
      wrappers[m] = std::make_unique<MuscleWrapper>(atlas, *muscles[m], atlas_dir, skeleton, bones,
                                                    rest_q, options, &separated);
      wrappers[m]->set_separation(separation.overlap_before_mm[m], separation.overlap_after_mm[m],
                                  separation.max_move_mm[m]);
    });
    std::vector<const Eigen::MatrixX3i*> faces;
    for (std::size_t m = 0; m < muscles.size(); ++m) {
      wrappers[m]->set_index(static_cast<int>(m));
      faces.push_back(&wrappers[m]->faces());
    }
    // Touching muscles share their motion across the interface (measured
    // on the separated rest surfaces).
    std::vector<std::vector<InterfaceLink>> interfaces;
    if (options.muscle_interface_reach_mm > 0.0) {
      std::vector<MatrixX3d> rest;
      rest.reserve(wrappers.size());
      for (const std::unique_ptr<MuscleWrapper>& wrapper : wrappers)
        rest.push_back(wrapper->rest_vertices());
      interfaces = muscle_interfaces(MuscleSurfaces(rest, faces, threads),
                                     options.muscle_interface_reach_mm, threads);
      for (std::size_t m = 0; m < muscles.size(); ++m)
        wrappers[m]->set_interface_vertices(static_cast<int>(interfaces[m].size()));
    }
    for (const VectorXd& q : frames) {
      const int stages = wrappers.front()->stages();
      for (int stage = 1; stage <= stages; ++stage) {
        const VectorXd q_stage = wrappers.front()->stage_coordinates(q, stage);
        parallel_for(muscles.size(), threads,
                     [&](std::size_t m) { wrappers[m]->prepare_stage(q_stage, stage == stages); });
        // Each muscle blends against the others' own targets, copied
        // before any is blended (only when there are interfaces).
        std::vector<MuscleBinding::Targets> unblended;
        std::vector<const MuscleBinding::Targets*> own_targets;
        if (!interfaces.empty()) {
          unblended.reserve(muscles.size());
          for (const std::unique_ptr<MuscleWrapper>& wrapper : wrappers) {
            unblended.push_back(wrapper->targets());
            own_targets.push_back(&unblended.back());
          }
        }
        parallel_for(muscles.size(), threads, [&](std::size_t m) {
          if (!interfaces.empty()) wrappers[m]->blend_targets(interfaces[m], own_targets);
          wrappers[m]->solve_stage();
        });
        if (options.joint_muscle_contacts) {
          const Clock::time_point joint_start = Clock::now();
          std::vector<JointBody> bodies(muscles.size());
          parallel_for(muscles.size(), threads,
                       [&](std::size_t m) { bodies[m] = wrappers[m]->joint_body(); });
          JointOptions joint;
          joint.coupling = options.muscle_contact;
          joint.max_rounds = options.joint_rounds;
          joint.threads = threads;
          JointResult solved = solve_jointly(bodies, joint);
          // Thread time, shared out evenly.
          const double share = seconds_since(joint_start) * threads / muscles.size();
          for (std::size_t m = 0; m < muscles.size(); ++m)
            wrappers[m]->take_joint_solve(std::move(solved.bodies[m]), share);
          continue;
        }
        // Rounds of shared contacts, each found on the last round's
        // surfaces and added to the pins of the rounds before; then the
        // settling rounds, where only the muscles still inside another move.
        // Settling moves only one side and can overshoot, so the pose keeps
        // the surfaces whose deepest entry into another muscle was the
        // shallowest, measured before every settling round and after the last.
        MusclePins pins(muscles.size());
        const int ramp = options.muscle_contact_rounds;
        const int settling_rounds = options.muscle_contact_settling_rounds;
        const int last_round = ramp + settling_rounds - (settling_rounds > 0 ? 0 : 1);
        double best_depth = std::numeric_limits<double>::infinity();
        std::vector<DeformResult> best;
        for (int round = 0; round <= last_round; ++round) {
          std::vector<MatrixX3d> positions;
          positions.reserve(wrappers.size());
          for (const std::unique_ptr<MuscleWrapper>& wrapper : wrappers)
            positions.push_back(wrapper->current());
          const MuscleSurfaces posed(positions, faces, threads);
          MuscleContactOptions round_contact = options.muscle_contact;
          const bool settling = round >= ramp;
          round_contact.share = settling ? 1.0 : round_share(round_contact.share, round, ramp);
          if (settling) round_contact.weight = options.deformer.contact_weight;
          std::vector<MuscleClearance> clearances;
          const std::vector<std::vector<Contact>> found =
              shared_muscle_contacts(positions, posed, round_contact, threads, &clearances);
          if (settling) {
            const double depth = longest_move(found, positions);
            if (depth < best_depth) {
              best_depth = depth;
              best.clear();
              for (const std::unique_ptr<MuscleWrapper>& wrapper : wrappers)
                best.push_back(wrapper->last_solve());
            } else if (round == last_round) {
              for (std::size_t m = 0; m < muscles.size(); ++m) wrappers[m]->restore_solve(best[m]);
            }
            if (round == last_round) break;  // measured only
          }
          if (!pins.add(found)) break;
          parallel_for(muscles.size(), threads, [&](std::size_t m) {
            if (settling && found[m].empty()) return;  // not inside another: it stands
            const std::vector<Contact> own = pins.of(m);
            wrappers[m]->solve_stage(&posed, &own, &clearances[m]);
          });
        }
      }
      parallel_for(muscles.size(), threads, [&](std::size_t m) { wrappers[m]->end_frame(q); });
    }
    for (std::size_t m = 0; m < muscles.size(); ++m) result.muscles[m] = wrappers[m]->take();
  }
  if ((options.muscle_penetration || options.muscle_contacts) && result.muscles.size() > 1) {
    const Clock::time_point measuring = Clock::now();
    measure_muscle_penetration(result, options.contacts.tolerance_mm, threads);
    result.muscle_penetration = true;
    result.muscle_penetration_seconds = seconds_since(measuring);
  }
  result.seconds = seconds_since(start);
  return result;
}

}  // namespace mmm::wrapping

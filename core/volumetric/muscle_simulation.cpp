#include "core/volumetric/muscle_simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "core/atlas/atlas_io.h"
#include "core/errors.h"
#include "core/mesh/laplacian.h"
#include "core/motion/skeleton.h"
#include "core/parallel_for.h"
#include "core/volumetric/coarse_embedding.h"
#include "core/volumetric/rest_binding.h"
#include "core/wrapping/muscle_penetration.h"
#include "core/wrapping/posed_skeleton.h"

namespace mmm::volumetric {
namespace {

using Clock = std::chrono::steady_clock;
using Eigen::Isometry3d;
using Eigen::VectorXd;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The lattice of the atlas's muscles (all bones carved out).
LabelledLattice atlas_lattice(const atlas::Atlas& atlas, const std::filesystem::path& dir,
                              const std::vector<const atlas::Muscle*>& muscles,
                              const LatticeOptions& options) {
  std::vector<mesh::IndexedMesh> surfaces;
  surfaces.reserve(muscles.size() + atlas.bones.size());
  for (const atlas::Muscle* m : muscles) surfaces.push_back(atlas::load_mesh(dir, m->meshes));
  for (const atlas::Bone& b : atlas.bones) surfaces.push_back(atlas::load_mesh(dir, b.meshes));
  std::vector<NamedSurface> muscle_surfaces;
  std::vector<NamedSurface> bone_surfaces;
  for (std::size_t m = 0; m < muscles.size(); ++m)
    muscle_surfaces.push_back({muscles[m]->name, &surfaces[m]});
  for (std::size_t b = 0; b < atlas.bones.size(); ++b)
    bone_surfaces.push_back({atlas.bones[b].name, &surfaces[muscles.size() + b]});
  return build_labelled_lattice(muscle_surfaces, bone_surfaces, options);
}

// A stored lattice reduced to the selected muscles, in their order (the
// others' cells emptied). Throws when a selected muscle is not in it.
LabelledLattice select_muscles(const LabelledLattice& stored,
                               const std::vector<const atlas::Muscle*>& muscles) {
  std::vector<std::uint16_t> relabel(stored.muscles.size() + 1, 0);
  LabelledLattice out = stored;
  out.muscles.clear();
  for (std::size_t m = 0; m < muscles.size(); ++m) {
    const auto found = std::ranges::find_if(
        stored.muscles, [&](const MuscleCells& c) { return c.name == muscles[m]->name; });
    if (found == stored.muscles.end()) {
      throw InvalidInputError("muscle simulation: the lattice has no muscle '" + muscles[m]->name +
                              "'; hint: build the lattice from the same atlas and muscles");
    }
    relabel[static_cast<std::size_t>(found - stored.muscles.begin()) + 1] =
        static_cast<std::uint16_t>(m + 1);
    out.muscles.push_back(*found);
  }
  for (std::uint16_t& label : out.label) label = relabel[label];
  return out;
}

double bending(const Eigen::SparseMatrix<double>& laplacian, const Eigen::MatrixX3d& x) {
  return (laplacian * x).squaredNorm();
}

}  // namespace

std::string_view interfaces_name(MuscleInterfaces interfaces) {
  switch (interfaces) {
    case MuscleInterfaces::kShared:
      return "shared";
    case MuscleInterfaces::kStick:
      return "stick";
    case MuscleInterfaces::kSlide:
      return "slide";
  }
  return "shared";
}

std::optional<MuscleInterfaces> interfaces_from_name(std::string_view name) {
  for (const MuscleInterfaces i :
       {MuscleInterfaces::kShared, MuscleInterfaces::kStick, MuscleInterfaces::kSlide}) {
    if (interfaces_name(i) == name) return i;
  }
  return std::nullopt;
}

namespace {

void check_options(const MuscleSimulationOptions& options) {
  if (options.coarsening < 1 || options.coarsening > 8) {
    throw InvalidInputError("muscle simulation: coarsening must be 1-8, got " +
                            std::to_string(options.coarsening));
  }
  if (!(options.attachment_reach_mm > 0) || !std::isfinite(options.attachment_reach_mm)) {
    throw InvalidInputError("muscle simulation: attachment_reach_mm must be a positive number");
  }
  if (options.first_frame_intermediate_poses < 0) {
    throw InvalidInputError("muscle simulation: first_frame_intermediate_poses must be >= 0");
  }
}

// Ties the model to the skeleton at rest (rest_binding.h): the muscles'
// surfaces (into `surfaces`), moved out of the bones; their attachment
// nodes; the element nodes anchored in the bones. Returns every driven node
// and records the counts in `result`.
std::vector<DrivenNode> bind_at_rest(EmbeddedModel& model,
                                     const std::vector<const atlas::Muscle*>& muscles,
                                     const wrapping::PosedBones& bones, double spacing,
                                     const MuscleSimulationOptions& options, int threads,
                                     std::vector<MuscleSurface>& surfaces,
                                     MuscleSimulation& result) {
  surfaces.resize(muscles.size());
  parallel_for(muscles.size(), threads, [&](std::size_t m) {
    surfaces[m] = muscle_surface(model.output, static_cast<std::uint16_t>(m + 1));
  });
  {
    std::vector<char> on_boundary(static_cast<std::size_t>(model.output.V.rows()), 0);
    for (const MuscleSurface& surface : surfaces) {
      for (const int node : surface.nodes) on_boundary[static_cast<std::size_t>(node)] = 1;
    }
    std::vector<int> boundary_nodes;
    for (std::size_t i = 0; i < on_boundary.size(); ++i) {
      if (on_boundary[i] != 0) boundary_nodes.push_back(static_cast<int>(i));
    }
    result.rest_moved_out_of_bones_mm =
        move_out_of_bones(model, boundary_nodes, bones, options.rest_clearance_mm,
                          spacing * std::sqrt(3.0), threads, result.rest_moved_nodes);
    for (MuscleSurface& surface : surfaces) {
      for (std::size_t v = 0; v < surface.nodes.size(); ++v)
        surface.rest.V.row(static_cast<Eigen::Index>(v)) = model.output.V.row(surface.nodes[v]);
    }
    const Eigen::VectorXd volumes = tet_volumes(model.output);
    result.rest_inverted_output = static_cast<int>((volumes.array() <= 0.0).count());
  }
  std::vector<DrivenNode> driven;
  std::vector<int> taken(static_cast<std::size_t>(model.output.V.rows()), -1);
  for (std::size_t m = 0; m < muscles.size(); ++m) {
    double gap = 0.0;
    int left_out = 0;
    const std::vector<DrivenNode> own = attachments(*muscles[m], surfaces[m], bones, taken,
                                                    options.attachment_reach_mm, gap, left_out);
    result.attachment_gap_mm.push_back(gap);
    result.attachments_left_out.push_back(left_out);
    for (const DrivenNode& d : own) taken[static_cast<std::size_t>(d.node)] = d.bone;
    result.driven_per_muscle.push_back(static_cast<int>(own.size()));
    driven.insert(driven.end(), own.begin(), own.end());
  }
  result.driven_nodes = static_cast<int>(driven.size());
  const std::vector<DrivenNode> anchors =
      !options.anchor_elements_in_bones
          ? std::vector<DrivenNode>{}
          : element_anchors(model.elements, bones, spacing * options.coarsening * std::sqrt(3.0),
                            options.anchor_joint_clearance_mm, threads);
  result.anchored_element_nodes = static_cast<int>(anchors.size());
  driven.insert(driven.end(), anchors.begin(), anchors.end());
  return driven;
}

}  // namespace

MuscleSimulation simulate_muscles(const atlas::Atlas& atlas, const std::filesystem::path& atlas_dir,
                                  const motion::FusedMotion& motion,
                                  const MuscleSimulationOptions& options,
                                  const LabelledLattice* lattice) {
  const Clock::time_point start = Clock::now();
  check_options(options);
  if (motion.num_frames() == 0)
    throw InvalidInputError("muscle simulation: the motion has no frame");
  const int threads = options.threads > 0 ? options.threads : machine_threads();
  std::vector<const atlas::Muscle*> muscles = wrapping::selected_muscles(atlas, options.muscles);
  if (lattice != nullptr && options.muscles.empty()) {
    muscles.clear();
    for (const MuscleCells& cells : lattice->muscles) {
      const atlas::Muscle* m = atlas.find_muscle(cells.name);
      if (m == nullptr) {
        throw InvalidInputError("muscle simulation: the lattice's muscle '" + cells.name +
                                "' is not in the atlas; hint: build the lattice from this atlas");
      }
      muscles.push_back(m);
    }
  }
  for (const atlas::Muscle* m : muscles) {
    if (m->action_lines.empty())
      throw InvalidInputError("muscle simulation: muscle '" + m->name + "' has no action line");
  }
  const motion::Skeleton skeleton = motion::skeleton_from_atlas(atlas);
  const VectorXd rest_q = wrapping::rest_coordinates(atlas, skeleton);
  const std::vector<VectorXd> frames = wrapping::frame_coordinates(motion, skeleton, rest_q);
  const wrapping::PosedBones bones = wrapping::load_bones(atlas, atlas_dir, skeleton);

  MuscleSimulation result;
  LatticeOptions lattice_options = options.lattice;
  lattice_options.threads = threads;
  const LabelledLattice labels = lattice != nullptr
                                     ? select_muscles(*lattice, muscles)
                                     : atlas_lattice(atlas, atlas_dir, muscles, lattice_options);
  result.lattice = labels.muscles;
  result.spacing_mm = labels.spacing_mm;
  result.coarsening = options.coarsening;
  EmbeddedModel model = options.interfaces == MuscleInterfaces::kShared
                            ? embed_in_coarse_lattice(labels, options.coarsening)
                            : embed_muscles_separately(labels, options.coarsening);
  result.interface_pairs = model.interfaces.size();

  std::vector<MuscleSurface> surfaces;
  const std::vector<DrivenNode> driven =
      bind_at_rest(model, muscles, bones, labels.spacing_mm, options, threads, surfaces, result);
  result.element_nodes = model.elements.V.rows();
  result.elements = model.elements.T.rows();
  result.output_nodes = model.output.V.rows();

  std::vector<const mesh::IndexedMesh*> bone_meshes;
  for (const wrapping::PosableBone& bone : bones.surfaces)
    bone_meshes.push_back(&bone.surface->tree().mesh());
  SimulationOptions simulation_options = options.simulation;
  simulation_options.threads = threads;
  simulation_options.slide = options.interfaces == MuscleInterfaces::kSlide;
  TetSimulation simulation(std::move(model), driven, bone_meshes, simulation_options);
  result.checked_nodes = simulation.checked_nodes();

  // Per muscle: the rest metrics and the action lines' routers.
  wrapping::MuscleWrapping& out = result.motion;
  out.times = motion.times;
  out.bone_names = bones.names;
  out.moment_arm_coordinates = options.moment_arm_coordinates;
  out.threads = threads;
  out.muscle_penetration = options.muscle_penetration;
  out.muscles.resize(muscles.size());
  std::vector<std::unique_ptr<wrapping::BoneContacts>> bone_depths(muscles.size());
  std::vector<Eigen::SparseMatrix<double>> laplacians(muscles.size());
  std::vector<double> rest_bending(muscles.size());
  std::vector<std::vector<wrapping::LineRouter>> routers(muscles.size());
  std::vector<wrapping::RoutingBone> routing_bones;  // the global method's obstacles
  if (options.routing.method == wrapping::PathMethod::kGlobal) {
    for (std::size_t b = 0; b < bones.names.size(); ++b)
      routing_bones.push_back({bones.surfaces[b].surface.get(), bones.bodies[b]});
  }
  parallel_for(muscles.size(), threads, [&](std::size_t m) {
    wrapping::WrappedMuscle& w = out.muscles[m];
    w.name = muscles[m]->name;
    w.rest = surfaces[m].rest;
    bone_depths[m] = std::make_unique<wrapping::BoneContacts>(w.rest.V, bones.surfaces);
    w.rest_penetration = bone_depths[m]->measure(
        w.rest.V, std::vector<Isometry3d>(bones.names.size(), Isometry3d::Identity()));
    laplacians[m] = mesh::cotangent_laplacian(w.rest.V, w.rest.F);
    rest_bending[m] = bending(laplacians[m], w.rest.V);
    w.rest_volume_mm3 = labels.muscles[m].kept_mm3;
    for (const atlas::ActionLine& line : muscles[m]->action_lines) {
      routers[m].emplace_back(atlas, *muscles[m], line, skeleton, routing_bones, options.routing);
      w.lines.push_back({line.name, {}, {}, {}});
    }
  });
  std::vector<wrapping::RestOverlap> rest_overlap(muscles.size());
  std::vector<const Eigen::MatrixX3i*> faces;
  for (const wrapping::WrappedMuscle& w : out.muscles) faces.push_back(&w.rest.F);
  if (options.muscle_penetration) {
    std::vector<Eigen::MatrixX3d> rest;
    for (const wrapping::WrappedMuscle& w : out.muscles) rest.push_back(w.rest.V);
    const wrapping::MuscleSurfaces at_rest(rest, faces, threads);
    parallel_for(muscles.size(), threads, [&](std::size_t m) {
      rest_overlap[m] = wrapping::rest_overlap(static_cast<int>(m), rest[m], at_rest);
    });
  }
  result.setup_seconds = seconds_since(start);

  motion::SkeletonPose pose(skeleton);
  const auto poses_at = [&](const VectorXd& q) {
    pose.set(q);
    return wrapping::bone_poses(pose, bones);
  };
  // From the rest pose to the first frame in small steps.
  for (int stage = 1; stage <= options.first_frame_intermediate_poses; ++stage) {
    const double t = static_cast<double>(stage) / (options.first_frame_intermediate_poses + 1);
    Clock::time_point since = Clock::now();
    simulation.step(poses_at((1.0 - t) * rest_q + t * frames.front()));
    result.simulation_seconds += seconds_since(since);
  }
  const auto arms = static_cast<Eigen::Index>(options.moment_arm_coordinates.size());
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const VectorXd& q = frames[f];
    const std::vector<Isometry3d> poses = poses_at(q);
    out.bone_poses.push_back(poses);
    Clock::time_point since = Clock::now();
    const FrameStats stats = simulation.step(poses);
    result.simulation_seconds += seconds_since(since);
    result.max_inverted = std::max(result.max_inverted, stats.inverted);
    result.max_interface_gap_mm = std::max(result.max_interface_gap_mm, stats.max_interface_gap_mm);
    result.max_interface_slide_mm =
        std::max(result.max_interface_slide_mm, stats.max_interface_slide_mm);
    const Eigen::MatrixX3d& y = simulation.positions();

    since = Clock::now();
    parallel_for(muscles.size(), threads, [&](std::size_t m) {
      wrapping::WrappedMuscle& w = out.muscles[m];
      for (std::size_t l = 0; l < routers[m].size(); ++l) {
        wrapping::LineRouter& router = routers[m][l];
        const wrapping::ActionLinePath path = router.route(q);
        wrapping::WrappedLine& record = w.lines[l];
        record.paths.push_back(path.points);
        record.lengths_mm.push_back(path.length);
        record.moment_arms_mm.conservativeResize(static_cast<Eigen::Index>(f) + 1, arms);
        for (Eigen::Index c = 0; c < arms; ++c) {
          const auto coordinate = skeleton.coordinate_index(
              options.moment_arm_coordinates[static_cast<std::size_t>(c)]);
          record.moment_arms_mm(static_cast<Eigen::Index>(f), c) =
              coordinate ? router.moment_arm(q, *coordinate)
                         : std::numeric_limits<double>::quiet_NaN();
        }
      }
    });
    result.lines_seconds += seconds_since(since);

    since = Clock::now();
    std::vector<Eigen::MatrixX3d> positions(muscles.size());
    for (std::size_t m = 0; m < muscles.size(); ++m) {
      positions[m].resize(static_cast<Eigen::Index>(surfaces[m].nodes.size()), 3);
      for (std::size_t v = 0; v < surfaces[m].nodes.size(); ++v)
        positions[m].row(static_cast<Eigen::Index>(v)) = y.row(surfaces[m].nodes[v]);
    }
    std::unique_ptr<wrapping::MuscleSurfaces> others;
    if (options.muscle_penetration)
      others = std::make_unique<wrapping::MuscleSurfaces>(positions, faces, threads);
    parallel_for(muscles.size(), threads, [&](std::size_t m) {
      wrapping::WrappedMuscle& w = out.muscles[m];
      wrapping::MuscleFrameMetrics metrics;
      metrics.volume_error_percent = 100.0 * stats.volume_change[m];
      const wrapping::PenetrationMetrics in_bones = bone_depths[m]->measure(positions[m], poses);
      metrics.max_depth_mm = in_bones.max_depth_mm;
      metrics.vertices_inside = in_bones.vertices_inside;
      metrics.vertices_deeper = in_bones.vertices_deeper;
      metrics.deepest_bone = in_bones.deepest_bone;
      if (others) {
        const wrapping::MusclePenetration depth = wrapping::measure_muscle_penetration(
            static_cast<int>(m), positions[m], *others, rest_overlap[m], 0.1);
        metrics.muscle_depth_mm = depth.max_depth_mm;
        metrics.muscle_vertices_deeper = depth.vertices_deeper;
        metrics.deepest_muscle = depth.deepest_muscle;
      }
      metrics.smoothness_change_percent =
          rest_bending[m] > 0
              ? 100.0 * (bending(laplacians[m], positions[m]) / rest_bending[m] - 1.0)
              : 0.0;
      metrics.converged = stats.inverted == 0;
      metrics.seconds = stats.seconds / static_cast<double>(muscles.size());
      w.frames.push_back(metrics);
      w.positions.emplace_back(positions[m].cast<float>());
    });
    result.measure_seconds += seconds_since(since);
    if (options.muscle_penetration) out.muscle_penetration_seconds = result.measure_seconds;
    result.frames.push_back(stats);
  }
  out.seconds = seconds_since(start);
  return result;
}

}  // namespace mmm::volumetric

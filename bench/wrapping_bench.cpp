// Muscle wrapping, both pathways. (1) The whole walk: subject01's trial
// (0.5-2.5 s, 121 frames) fitted to its OpenSim model, retargeted to the
// default atlas, and every atlas muscle wrapped at every frame (volume held,
// out of the bones): per-muscle volume error, penetration, bending change and
// time beside the reference implementation's figures (VPHOP D10.2, section
// 3.4.2); plot in $MMM_BENCH_OUT_DIR/wrapping_metrics.svg; then the same
// walk with the volumetric pathway (core/volumetric/muscle_simulation.h,
// MMM_BENCH_WRAPPING_PATHWAYS picks either). (2) The action
// lines' hip-flexion moment arms on the default atlas (gait2392's paths
// carried onto the Visible Human Female's bones) beside the gait2392
// model's own, over hip flexion -20..60 degrees. (3) Google Benchmark: a
// path and moment-arm evaluation of every line; ten frames of one muscle.
//
// The table goes to stdout and $MMM_BENCH_OUT_DIR/wrapping.accuracy.{txt,json}
// (bench/table.py folds them into build/bench/wrapping.json).

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <algorithm>
#include "bench/bench_main.h"
#include "core/atlas/atlas_io.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/signed_distance.h"
#include "core/motion/marker_mapping.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/retarget.h"
#include "core/motion/skeleton.h"
#include "core/opensim/osim_model.h"
#include "core/opensim/trc.h"
#include "core/plot/svg_plot.h"
#include "core/volumetric/muscle_simulation.h"
#include "core/wrapping/action_line_path.h"
#include "core/wrapping/line_router.h"
#include "core/wrapping/muscle_frames.h"
#include "core/wrapping/muscle_wrapping.h"
#include "core/wrapping/osim_action_lines.h"
#include "core/wrapping/wrapping_summary.h"

namespace {

// The wrapping nodes' default animation_stride: the wrapped-motion artifact
// (core/wrapping/muscle_frames.h) holds every 5th frame.
constexpr int kArtifactStride = 5;

double wrapped_motion_mb(const mmm::wrapping::MuscleWrapping& wrapped) {
  return static_cast<double>(mmm::wrapping::encode_muscle_frames(
                                 mmm::wrapping::muscle_frames(wrapped, kArtifactStride, "bench"))
                                 .size()) /
         1e6;
}

namespace motion = mmm::motion;
namespace wrapping = mmm::wrapping;
namespace volumetric = mmm::volumetric;
constexpr double kDeg = std::numbers::pi / 180.0;

struct Models {
  mmm::atlas::Atlas atlas;
  motion::Skeleton atlas_skeleton;
  mmm::atlas::Atlas gait2392;
  motion::Skeleton gait2392_skeleton;
};

const Models& models() {
  static const Models data = [] {
    Models m;
    const char* dir = std::getenv("MMM_BENCH_ATLAS");
    m.atlas = mmm::atlas::read_atlas(dir != nullptr ? dir : "build/atlas/vhf_right_leg");
    m.atlas_skeleton = motion::skeleton_from_atlas(m.atlas);
    const mmm::opensim::OsimModel model = mmm::opensim::read_osim(
        std::filesystem::path(MMM_DATA_DIR) / "gait2392" / "gait2392_thelen2003muscle.osim");
    m.gait2392 = wrapping::osim_action_lines(model);
    m.gait2392_skeleton = motion::skeleton_from_osim(model);
    return m;
  }();
  return data;
}

std::filesystem::path atlas_dir() {
  const char* dir = std::getenv("MMM_BENCH_ATLAS");
  return dir != nullptr ? dir : "build/atlas/vhf_right_leg";
}

// Every bone of the default atlas with a mesh, as a signed distance (full
// level) carried by its skeleton body: the obstacles of global paths.
const std::vector<wrapping::RoutingBone>& atlas_routing_bones() {
  static const std::vector<std::unique_ptr<mmm::mesh::SignedDistance>> surfaces = [] {
    std::vector<std::unique_ptr<mmm::mesh::SignedDistance>> result;
    for (const mmm::atlas::Bone& bone : models().atlas.bones) {
      if (bone.meshes.empty() || !models().atlas_skeleton.body_index(bone.name)) continue;
      const mmm::atlas::MeshLevel* level = &bone.meshes.front();
      for (const mmm::atlas::MeshLevel& l : bone.meshes) {
        if (l.level == "full") level = &l;
      }
      result.push_back(std::make_unique<mmm::mesh::SignedDistance>(
          mmm::mesh::read_mesh(atlas_dir() / level->file)));
    }
    return result;
  }();
  static const std::vector<wrapping::RoutingBone> bones = [] {
    std::vector<wrapping::RoutingBone> result;
    std::size_t k = 0;
    for (const mmm::atlas::Bone& bone : models().atlas.bones) {
      const auto body = models().atlas_skeleton.body_index(bone.name);
      if (bone.meshes.empty() || !body) continue;
      result.push_back({surfaces[k++].get(), *body});
    }
    return result;
  }();
  return bones;
}

// Hip-flexion moment arm (mm) of one line at each angle (deg), everything
// else at its default; the angles in order (a global path follows them).
std::vector<double> hip_flexion_arms(
    const mmm::atlas::Atlas& atlas, const motion::Skeleton& skeleton,
    const mmm::atlas::Muscle& muscle, const mmm::atlas::ActionLine& line,
    const std::vector<double>& angles,
    wrapping::PathMethod method = wrapping::PathMethod::kObstacleSet) {
  const int hip = *skeleton.coordinate_index("hip_flexion_r");
  wrapping::RouterOptions options;
  options.method = method;
  wrapping::LineRouter router(atlas, muscle, line, skeleton,
                              method == wrapping::PathMethod::kGlobal
                                  ? atlas_routing_bones()
                                  : std::vector<wrapping::RoutingBone>{},
                              options);
  std::vector<double> arms;
  for (const double angle : angles) {
    Eigen::VectorXd q = skeleton.default_coordinates();
    q(hip) = angle * kDeg;
    (void)router.route(q);
    arms.push_back(router.moment_arm(q, hip));
  }
  return arms;
}

// subject01's walk, 0.5-2.5 s, fitted to its OpenSim model and retargeted to
// the default atlas (what fuse_motion does in schemas/examples/muscle_wrapping.yaml).
const motion::FusedMotion& atlas_walk() {
  static const motion::FusedMotion walk = [] {
    const std::filesystem::path pipelines =
        std::filesystem::path(MMM_DATA_DIR) / "gait2392" / "Pipelines";
    const motion::Skeleton subject = motion::skeleton_from_osim(
        mmm::opensim::read_osim(pipelines / "reference" / "subject01_simbody.osim"));
    const mmm::opensim::MarkerTrajectories trial =
        mmm::opensim::read_trc(pipelines / "subject01_walk1.trc");
    const motion::MarkerMapping mapping = motion::gait2392_marker_mapping();
    motion::MotionFusionOptions options;
    options.start_time = 0.5;
    options.end_time = 2.5;
    const motion::FusedMotion fitted = motion::fuse_motion(subject, trial, mapping, options);
    return motion::retarget_motion(fitted, subject, models().atlas_skeleton, trial, mapping).motion;
  }();
  return walk;
}

struct WalkSummary {
  double max_volume_percent = 0.0;
  double max_depth_mm = 0.0;
  double max_bending_percent = 0.0;
  int vertex_frames_deeper = 0;
  double median_ms = 0.0;
  double seconds = 0.0;
  bool muscle_penetration = false;  // measured
  double max_muscle_depth_mm = 0.0;
  int muscle_vertex_frames_deeper = 0;
  double median_muscle_depth_mm = 0.0;  // over muscle-frames
  double p99_muscle_depth_mm = 0.0;
  double p99_bending_percent = 0.0;
};

// The value below which a fraction q of `values` lies (nearest rank; 0 when empty).
double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

WalkSummary summarise_walk(const wrapping::MuscleWrapping& wrapped) {
  WalkSummary walk;
  std::vector<double> all_ms;
  std::vector<double> depths;    // per muscle-frame, in other muscles
  std::vector<double> bendings;  // per muscle-frame
  for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
    const wrapping::MuscleWrappingSummary summary = wrapping::summarise(muscle);
    walk.max_volume_percent =
        std::max(walk.max_volume_percent, summary.max_abs_volume_error_percent);
    walk.max_depth_mm = std::max(walk.max_depth_mm, summary.max_depth_mm);
    walk.max_bending_percent =
        std::max(walk.max_bending_percent, summary.max_smoothness_change_percent);
    walk.vertex_frames_deeper += summary.vertex_frames_deeper;
    walk.max_muscle_depth_mm = std::max(walk.max_muscle_depth_mm, summary.max_muscle_depth_mm);
    walk.muscle_vertex_frames_deeper += summary.muscle_vertex_frames_deeper;
    for (const wrapping::MuscleFrameMetrics& frame : muscle.frames) {
      depths.push_back(frame.muscle_depth_mm);
      bendings.push_back(frame.smoothness_change_percent);
    }
    all_ms.insert(all_ms.end(), summary.ms_per_frame.begin(), summary.ms_per_frame.end());
  }
  walk.median_ms = wrapping::median(all_ms);
  walk.seconds = wrapped.seconds - wrapped.muscle_penetration_seconds;  // the wrapping itself
  walk.muscle_penetration = wrapped.muscle_penetration;
  walk.median_muscle_depth_mm = quantile(depths, 0.5);
  walk.p99_muscle_depth_mm = quantile(depths, 0.99);
  walk.p99_bending_percent = quantile(bendings, 0.99);
  return walk;
}

// The whole walk with other options than the default, one summary line each.
nlohmann::json write_variants_table(std::ostringstream& out, const WalkSummary& baseline) {
  struct Variant {
    std::string name;
    wrapping::MuscleWrappingOptions options;
  };
  std::vector<Variant> variants(5);
  variants[0].name = "direct (no hull)";
  variants[0].options.coarse_to_fine = false;
  variants[1].name = "global paths";
  variants[1].options.routing.method = wrapping::PathMethod::kGlobal;
  variants[2].name = "muscle contacts";
  variants[2].options.muscle_contacts = true;
  variants[3].name = "muscle contacts, joint";
  variants[3].options.muscle_contacts = true;
  variants[3].options.joint_muscle_contacts = true;
  variants[4].name = "muscle contacts, settled";
  variants[4].options.muscle_contacts = true;
  variants[4].options.muscle_contact_settling_rounds = 6;
  // MMM_BENCH_WRAPPING_VARIANTS: the 0-based indices of the variants to run
  // ("2,3"); unset: all of them.
  if (const char* only = std::getenv("MMM_BENCH_WRAPPING_VARIANTS"); only != nullptr) {
    std::vector<Variant> chosen;
    std::istringstream list(only);
    for (std::string index; std::getline(list, index, ',');) {
      const auto k = static_cast<std::size_t>(std::stoul(index));
      if (k < variants.size()) chosen.push_back(variants[k]);
    }
    variants = std::move(chosen);
  }
  out << "\nvariants over the same walk\n"
      << std::left << std::setw(26) << "variant" << std::setw(14) << "|vol err| %" << std::setw(12)
      << "depth mm" << std::setw(14) << "max bending %" << std::setw(12) << "median ms"
      << std::setw(14) << "whole walk s" << std::setw(14) << "p99 bending %"
      << "in other muscles mm: median / p99 / max muscle-frame, vertex-frames deeper\n";
  nlohmann::json rows = nlohmann::json::array();
  const auto row = [&](const std::string& name, const WalkSummary& walk) {
    out << std::setw(26) << name << std::setw(14) << std::scientific << std::setprecision(1)
        << walk.max_volume_percent << std::fixed << std::setw(12) << std::setprecision(2)
        << walk.max_depth_mm << std::setw(14) << std::setprecision(0) << walk.max_bending_percent
        << std::setw(12) << std::setprecision(1) << walk.median_ms << std::setw(14) << walk.seconds
        << std::setw(14) << std::setprecision(0) << walk.p99_bending_percent
        << std::setprecision(2);
    if (walk.muscle_penetration) {
      out << walk.median_muscle_depth_mm << " / " << walk.p99_muscle_depth_mm << " / "
          << walk.max_muscle_depth_mm << ", " << walk.muscle_vertex_frames_deeper;
    } else {
      out << "-";
    }
    out << "\n";
    rows.push_back({{"variant", name},
                    {"max_abs_volume_error_percent", walk.max_volume_percent},
                    {"max_depth_mm", walk.max_depth_mm},
                    {"max_bending_change_percent", walk.max_bending_percent},
                    {"vertex_frames_deeper_than_tolerance", walk.vertex_frames_deeper},
                    {"median_ms_per_muscle_frame", walk.median_ms},
                    {"whole_walk_s", walk.seconds},
                    {"muscle_penetration_measured", walk.muscle_penetration},
                    {"max_depth_in_other_muscles_mm", walk.max_muscle_depth_mm},
                    {"median_depth_in_other_muscles_mm", walk.median_muscle_depth_mm},
                    {"p99_depth_in_other_muscles_mm", walk.p99_muscle_depth_mm},
                    {"p99_bending_change_percent", walk.p99_bending_percent},
                    {"vertex_frames_deeper_in_other_muscles", walk.muscle_vertex_frames_deeper}});
  };
  row("coarse to fine (default)", baseline);
  for (const Variant& variant : variants) {
    row(variant.name, summarise_walk(wrapping::wrap_muscles(models().atlas, atlas_dir(),
                                                            atlas_walk(), variant.options)));
  }
  return rows;
}

nlohmann::json write_trial_table(std::ostringstream& out) {
  mmm::wrapping::MuscleWrappingOptions options;
  options.muscle_penetration = true;  // the metric, timed apart
  const wrapping::MuscleWrapping wrapped =
      wrapping::wrap_muscles(models().atlas, atlas_dir(), atlas_walk(), options);
  out << "\nwhole walk, energy pathway with bone impenetrability: " << wrapped.muscles.size()
      << " muscles x " << wrapped.times.size()
      << " frames (subject01_walk1 0.5-2.5 s retargeted to the default atlas), " << wrapped.threads
      << " threads\n"
      << std::left << std::setw(30) << "muscle" << std::setw(8) << "faces" << std::setw(14)
      << "|vol err| %" << std::setw(12) << "depth mm" << std::setw(12) << "bending %"
      << std::setw(12) << "median ms" << std::setw(10) << "setup s" << std::setw(32)
      << "hull faces / build s / outside"
      << "in other muscles mm (vs rest)\n";
  nlohmann::json rows = nlohmann::json::array();
  std::vector<double> all_ms;
  std::vector<double> ten_k_ms;
  double worst_volume = 0.0;
  double worst_depth = 0.0;
  int deeper = 0;
  for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
    const wrapping::MuscleWrappingSummary summary = wrapping::summarise(muscle);
    const std::vector<double>& ms = summary.ms_per_frame;
    const double volume = summary.max_abs_volume_error_percent;
    const double depth = summary.max_depth_mm;
    const double bending = summary.max_smoothness_change_percent;
    deeper += summary.vertex_frames_deeper;
    all_ms.insert(all_ms.end(), ms.begin(), ms.end());
    if (muscle.rest.F.rows() >= 9000) ten_k_ms.insert(ten_k_ms.end(), ms.begin(), ms.end());
    worst_volume = std::max(worst_volume, volume);
    worst_depth = std::max(worst_depth, depth);
    out << std::setw(30) << muscle.name << std::setw(8) << muscle.rest.F.rows() << std::setw(14)
        << std::scientific << std::setprecision(1) << volume << std::fixed << std::setw(12)
        << std::setprecision(2) << depth << std::setw(12) << std::setprecision(0) << bending
        << std::setw(12) << std::setprecision(1) << wrapping::median(ms) << std::setw(10)
        << std::setprecision(2) << muscle.setup_seconds << std::setw(32)
        << (std::to_string(muscle.hull_faces) + " / " +
            std::to_string(muscle.hull_build_seconds).substr(0, 4) + " / " +
            std::to_string(muscle.hull_vertices_outside))
        << std::setprecision(1) << summary.max_muscle_depth_mm << "\n";
    rows.push_back(
        {{"muscle", muscle.name},
         {"faces", muscle.rest.F.rows()},
         {"max_abs_volume_error_percent", volume},
         {"max_depth_mm", depth},
         {"max_bending_change_percent", bending},
         {"median_ms_per_frame", wrapping::median(ms)},
         {"setup_s", muscle.setup_seconds},
         {"hull_faces", muscle.hull_faces},
         {"hull_build_s", muscle.hull_build_seconds},
         {"hull_vertices_outside", muscle.hull_vertices_outside},
         {"max_depth_in_other_muscles_mm", summary.max_muscle_depth_mm},
         {"vertex_frames_deeper_in_other_muscles", summary.muscle_vertex_frames_deeper}});
  }
  out << std::setprecision(3) << "all: max |volume error| " << std::scientific << worst_volume
      << std::fixed
      << " % (target 0.5, stretch 0.1; reference: < 0.04 % without collisions, 7.45 % gluteus "
         "maximus with "
         "bones), max depth "
      << worst_depth << " mm (target 1), vertex-frames deeper than the contact tolerance " << deeper
      << "\n"
      << std::setprecision(1) << "median per muscle-frame " << wrapping::median(all_ms)
      << " ms; 9-10K-face muscles " << wrapping::median(ten_k_ms)
      << " ms (target 50; reference 500 ms without collisions, 23 s with bones, "
      << "20.1 s gluteus maximus)\n"
      << "whole walk " << wrapped.seconds - wrapped.muscle_penetration_seconds << " s on "
      << wrapped.threads
      << " threads (target 60 s; reference 188.6 s); measuring muscle-muscle penetration (the "
         "metric; muscles not kept apart) "
      << wrapped.muscle_penetration_seconds << " s more\n";
  // The plot of volume error, depth, time and bending over the walk.
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  mmm::plot::write_svg(
      wrapping::wrapping_metrics_svg(wrapped,
                                     "Muscle wrapping over subject01's walk on the default atlas"),
      std::filesystem::path(out_dir != nullptr ? out_dir : ".") / "wrapping_metrics.svg");
  const nlohmann::json variants = write_variants_table(out, summarise_walk(wrapped));
  const double artifact_mb = wrapped_motion_mb(wrapped);
  out << "wrapped motion (every " << kArtifactStride << "th frame, binary): " << artifact_mb
      << " MB\n";
  return {{"muscles", rows},
          {"variants", variants},
          {"wrapped_motion_mb", artifact_mb},
          {"frames", wrapped.times.size()},
          {"threads", wrapped.threads},
          {"whole_walk_s", wrapped.seconds - wrapped.muscle_penetration_seconds},
          {"muscle_penetration_s", wrapped.muscle_penetration_seconds},
          {"median_ms_per_muscle_frame", wrapping::median(all_ms)},
          {"median_ms_per_10k_face_muscle_frame", wrapping::median(ten_k_ms)},
          {"max_abs_volume_error_percent", worst_volume},
          {"max_depth_mm", worst_depth},
          {"vertex_frames_deeper_than_tolerance", deeper},
          {"reference",
           {{"ms_per_10k_muscle_without_collisions", 500},
            {"s_per_muscle_with_bones", 23},
            {"gluteus_maximus_s", 20.1},
            {"gluteus_maximus_volume_error_percent", 7.45},
            {"whole_walk_s", 188.6}}}};
}

// The volumetric pathway over the same walk: every muscle in one
// conforming tetrahedral model (3 mm lattice, 6 mm elements by default;
// MMM_BENCH_VOLUMETRIC="spacing,coarsening,rounds" to try others).
nlohmann::json write_volumetric_table(std::ostringstream& out) {
  volumetric::MuscleSimulationOptions options;
  if (const char* chosen = std::getenv("MMM_BENCH_VOLUMETRIC"); chosen != nullptr) {
    char comma = 0;
    std::istringstream(chosen) >> options.lattice.spacing_mm >> comma >> options.coarsening >>
        comma >> options.simulation.iterations;
  }
  options.anchor_elements_in_bones = std::getenv("MMM_BENCH_VOLUMETRIC_NO_ANCHORS") == nullptr;
  if (const char* clearance = std::getenv("MMM_BENCH_VOLUMETRIC_JOINT_CLEARANCE"))
    options.anchor_joint_clearance_mm = std::stod(clearance);
  // MMM_BENCH_VOLUMETRIC_WEIGHTS="shape,volume,contact,attachment reach mm".
  if (const char* weights = std::getenv("MMM_BENCH_VOLUMETRIC_WEIGHTS"); weights != nullptr) {
    char comma = 0;
    std::istringstream(weights) >> options.simulation.shape_weight >> comma >>
        options.simulation.volume_weight >> comma >> options.simulation.contact_weight >> comma >>
        options.attachment_reach_mm;
  }
  // MMM_BENCH_VOLUMETRIC_INTERFACES=shared|stick|slide, and
  // MMM_BENCH_VOLUMETRIC_INTERFACE_WEIGHT for the ties of the last two.
  if (const char* interfaces = std::getenv("MMM_BENCH_VOLUMETRIC_INTERFACES")) {
    options.interfaces = volumetric::interfaces_from_name(interfaces)
                             .value_or(volumetric::MuscleInterfaces::kShared);
  }
  if (const char* weight = std::getenv("MMM_BENCH_VOLUMETRIC_INTERFACE_WEIGHT"))
    options.simulation.interface_weight = std::stod(weight);
  // MMM_BENCH_VOLUMETRIC_FRAMES: only the first n frames.
  motion::FusedMotion walk_frames = atlas_walk();
  if (const char* frames = std::getenv("MMM_BENCH_VOLUMETRIC_FRAMES"); frames != nullptr) {
    const Eigen::Index n = std::min<Eigen::Index>(std::stoi(frames), walk_frames.num_frames());
    walk_frames.times.conservativeResize(n);
    walk_frames.coordinates.conservativeResize(n, Eigen::NoChange);
  }
  // MMM_BENCH_VOLUMETRIC_STILL: every frame at the atlas's rest coordinates
  // (the model moved rigidly by the skeleton's root).
  if (std::getenv("MMM_BENCH_VOLUMETRIC_STILL") != nullptr) {
    for (const mmm::atlas::Joint& joint : models().atlas.joints) {
      for (const mmm::atlas::Coordinate& coordinate : joint.coordinates) {
        if (const auto column = walk_frames.coordinate_index(coordinate.name))
          walk_frames.coordinates.col(*column).setConstant(coordinate.rest_value);
      }
    }
  }
  const volumetric::MuscleSimulation simulated =
      volumetric::simulate_muscles(models().atlas, atlas_dir(), walk_frames, options);
  const WalkSummary walk = summarise_walk(simulated.motion);
  std::vector<double> frame_ms;
  std::vector<double> local_ms;
  std::vector<double> contact_ms;
  std::vector<double> solve_ms;
  std::vector<double> volume_ms;
  for (const volumetric::FrameStats& frame : simulated.frames) {
    frame_ms.push_back(1000.0 * frame.seconds);
    local_ms.push_back(1000.0 * frame.local_seconds);
    contact_ms.push_back(1000.0 * frame.contact_seconds);
    solve_ms.push_back(1000.0 * frame.solve_seconds);
    volume_ms.push_back(1000.0 * frame.volume_seconds);
  }
  const double whole =
      simulated.setup_seconds + simulated.simulation_seconds + simulated.lines_seconds;
  out << "\nwhole walk, volumetric pathway: " << simulated.motion.muscles.size() << " muscles x "
      << simulated.frames.size() << " frames, lattice " << std::fixed << std::setprecision(1)
      << simulated.spacing_mm << " mm, elements x" << simulated.coarsening << " ("
      << simulated.element_nodes << " nodes, " << simulated.elements << " tetrahedra; "
      << simulated.output_nodes << " output nodes, " << simulated.driven_nodes << " driven, "
      << simulated.checked_nodes << " checked against bones, " << simulated.anchored_element_nodes
      << " element nodes inside bones; at rest " << simulated.rest_moved_nodes
      << " surface nodes moved out of bones by up to " << simulated.rest_moved_out_of_bones_mm
      << " mm, " << simulated.rest_inverted_output << " fine tetrahedra inverted by it), "
      << options.simulation.iterations << " rounds per frame, " << simulated.motion.threads
      << " threads; interfaces " << volumetric::interfaces_name(options.interfaces) << " ("
      << simulated.interface_pairs << " tied pairs; at worst " << std::setprecision(2)
      << simulated.max_interface_gap_mm << " mm across, " << simulated.max_interface_slide_mm
      << " mm along)\n"
      << "  worst volume error " << std::scientific << std::setprecision(1)
      << walk.max_volume_percent << " %, deepest in bone " << std::fixed << std::setprecision(2)
      << walk.max_depth_mm << " mm, in other muscles median / p99 / max "
      << walk.median_muscle_depth_mm << " / " << walk.p99_muscle_depth_mm << " / "
      << walk.max_muscle_depth_mm << " mm (" << walk.muscle_vertex_frames_deeper
      << " vertex-frames deeper than 0.1 mm), inverted elements at worst " << simulated.max_inverted
      << ", bending change p99 / max " << std::setprecision(0) << walk.p99_bending_percent << " / "
      << walk.max_bending_percent << " %\n"
      << "  time: setup " << std::setprecision(1) << simulated.setup_seconds << " s, simulation "
      << simulated.simulation_seconds << " s (median " << std::setprecision(0)
      << wrapping::median(frame_ms) << " ms per frame: local " << wrapping::median(local_ms)
      << ", contacts " << wrapping::median(contact_ms) << ", solves " << wrapping::median(solve_ms)
      << ", volumes " << wrapping::median(volume_ms) << "), action lines " << std::setprecision(1)
      << simulated.lines_seconds << " s, whole walk " << whole << " s; measurements "
      << simulated.measure_seconds << " s\n";
  out << "  " << std::left << std::setw(30) << "muscle" << std::setw(12) << "faces" << std::setw(14)
      << "|vol err| %" << std::setw(24) << "depth in bone mm (bone)"
      << "depth in other muscles mm (muscle)\n";
  nlohmann::json rows = nlohmann::json::array();
  for (const wrapping::WrappedMuscle& muscle : simulated.motion.muscles) {
    const wrapping::MuscleWrappingSummary summary = wrapping::summarise(muscle);
    std::string bone;
    std::string other;
    double deepest_bone = -1.0;
    double deepest_other = -1.0;
    for (const wrapping::MuscleFrameMetrics& frame : muscle.frames) {
      if (frame.max_depth_mm > deepest_bone) {
        deepest_bone = frame.max_depth_mm;
        bone = frame.deepest_bone;
      }
      if (frame.muscle_depth_mm > deepest_other && frame.deepest_muscle >= 0) {
        deepest_other = frame.muscle_depth_mm;
        other = simulated.motion.muscles[static_cast<std::size_t>(frame.deepest_muscle)].name;
      }
    }
    std::ostringstream depth;
    depth << std::fixed << std::setprecision(2) << summary.max_depth_mm << " (" << bone << ")";
    const auto index = static_cast<std::size_t>(&muscle - simulated.motion.muscles.data());
    out << "  " << std::setw(30) << muscle.name << std::setw(12) << muscle.rest.F.rows()
        << std::setw(14) << std::scientific << std::setprecision(1)
        << summary.max_abs_volume_error_percent << std::fixed << std::setw(24) << depth.str()
        << std::setprecision(2) << summary.max_muscle_depth_mm << " (" << other << ")"
        << "  attachments " << simulated.driven_per_muscle[index] << " nodes, gap "
        << std::setprecision(1) << simulated.attachment_gap_mm[index] << " mm, left out "
        << simulated.attachments_left_out[index] << "\n";
    rows.push_back({{"muscle", muscle.name},
                    {"faces", muscle.rest.F.rows()},
                    {"max_abs_volume_error_percent", summary.max_abs_volume_error_percent},
                    {"max_depth_mm", summary.max_depth_mm},
                    {"deepest_bone", bone},
                    {"max_depth_in_other_muscles_mm", summary.max_muscle_depth_mm},
                    {"deepest_other_muscle", other}});
  }
  std::vector<int> inverted;
  std::vector<int> inverted_per_muscle(simulated.motion.muscles.size(), 0);  // worst frame
  for (const volumetric::FrameStats& frame : simulated.frames) {
    inverted.push_back(frame.inverted);
    for (std::size_t m = 0; m < inverted_per_muscle.size() && m < frame.inverted_per_label.size();
         ++m) {
      inverted_per_muscle[m] = std::max(inverted_per_muscle[m], frame.inverted_per_label[m]);
    }
  }
  const double artifact_mb = wrapped_motion_mb(simulated.motion);
  out << "  wrapped motion (every " << kArtifactStride << "th frame, binary): " << artifact_mb
      << " MB\n";
  out << "  inverted elements per muscle, worst frame:";
  for (std::size_t m = 0; m < inverted_per_muscle.size(); ++m) {
    if (inverted_per_muscle[m] > 0)
      out << " " << simulated.motion.muscles[m].name << " " << inverted_per_muscle[m];
  }
  out << "\n";
  return {{"muscles", simulated.motion.muscles.size()},
          {"per_muscle", rows},
          {"inverted_per_frame", inverted},
          {"frames", simulated.frames.size()},
          {"spacing_mm", simulated.spacing_mm},
          {"coarsening", simulated.coarsening},
          {"rounds", options.simulation.iterations},
          {"interfaces", std::string(volumetric::interfaces_name(options.interfaces))},
          {"interface_pairs", simulated.interface_pairs},
          {"max_interface_gap_mm", simulated.max_interface_gap_mm},
          {"max_interface_slide_mm", simulated.max_interface_slide_mm},
          {"element_nodes", simulated.element_nodes},
          {"elements", simulated.elements},
          {"output_nodes", simulated.output_nodes},
          {"driven_nodes", simulated.driven_nodes},
          {"anchored_element_nodes", simulated.anchored_element_nodes},
          {"rest_moved_nodes", simulated.rest_moved_nodes},
          {"rest_moved_out_of_bones_mm", simulated.rest_moved_out_of_bones_mm},
          {"rest_inverted_output", simulated.rest_inverted_output},
          {"checked_nodes", simulated.checked_nodes},
          {"threads", simulated.motion.threads},
          {"max_abs_volume_error_percent", walk.max_volume_percent},
          {"max_depth_mm", walk.max_depth_mm},
          {"median_depth_in_other_muscles_mm", walk.median_muscle_depth_mm},
          {"p99_depth_in_other_muscles_mm", walk.p99_muscle_depth_mm},
          {"max_depth_in_other_muscles_mm", walk.max_muscle_depth_mm},
          {"vertex_frames_deeper_in_other_muscles", walk.muscle_vertex_frames_deeper},
          {"max_inverted_elements", simulated.max_inverted},
          {"p99_bending_change_percent", walk.p99_bending_percent},
          {"max_bending_change_percent", walk.max_bending_percent},
          {"setup_s", simulated.setup_seconds},
          {"simulation_s", simulated.simulation_seconds},
          {"median_ms_per_frame", wrapping::median(frame_ms)},
          {"lines_s", simulated.lines_seconds},
          {"whole_walk_s", whole},
          {"measurements_s", simulated.measure_seconds},
          {"wrapped_motion_mb", artifact_mb}};
}

void write_accuracy_table() {
  const Models& m = models();
  // MMM_BENCH_WRAPPING_PATHWAYS: "energy", "volumetric" or both (unset).
  const char* pathways = std::getenv("MMM_BENCH_WRAPPING_PATHWAYS");
  const auto wanted = [&](const std::string& name) {
    return pathways == nullptr || std::string(pathways).find(name) != std::string::npos;
  };
  std::ostringstream trial_out;
  const nlohmann::json trial = wanted("energy") ? write_trial_table(trial_out) : nlohmann::json{};
  const nlohmann::json volumetric =
      wanted("volumetric") ? write_volumetric_table(trial_out) : nlohmann::json{};
  std::cout << trial_out.str();
  std::vector<double> angles;
  for (int a = -20; a <= 60; a += 10) angles.push_back(a);
  std::ostringstream out;
  out << "\nhip-flexion moment arms (mm, + flexor): default atlas (VHF bones) vs the gait2392 "
         "model, hip flexion -20..60 deg, other joints at 0\n"
      << std::left << std::setw(16) << "action line" << std::setw(20) << "gait2392 -20/20/60"
      << std::setw(20) << "obstacle set" << std::setw(20) << "global (bones)"
      << "RMS difference obstacle set / global\n";
  nlohmann::json rows = nlohmann::json::array();
  std::vector<double> obstacle_rms;
  std::vector<double> global_rms_all;
  for (const mmm::atlas::Muscle& muscle : m.atlas.muscles) {
    for (const mmm::atlas::ActionLine& line : muscle.action_lines) {
      const mmm::atlas::Muscle* theirs = m.gait2392.find_muscle(line.name);
      if (theirs == nullptr) continue;
      const std::vector<double> ours =
          hip_flexion_arms(m.atlas, m.atlas_skeleton, muscle, line, angles);
      const std::vector<double> global = hip_flexion_arms(m.atlas, m.atlas_skeleton, muscle, line,
                                                          angles, wrapping::PathMethod::kGlobal);
      const std::vector<double> reference = hip_flexion_arms(
          m.gait2392, m.gait2392_skeleton, *theirs, theirs->action_lines.front(), angles);
      const auto rms_from_reference = [&](const std::vector<double>& arms) {
        double squares = 0;
        for (std::size_t i = 0; i < angles.size(); ++i)
          squares += (arms[i] - reference[i]) * (arms[i] - reference[i]);
        return std::sqrt(squares / static_cast<double>(angles.size()));
      };
      const double rms = rms_from_reference(ours);
      const double global_rms = rms_from_reference(global);
      if (std::abs(reference[4]) < 5.0 && std::abs(ours[4]) < 5.0) continue;  // not a hip muscle
      const auto triple = [](const std::vector<double>& v) {
        std::ostringstream t;
        t << std::fixed << std::setprecision(0) << v[0] << "/" << v[4] << "/" << v[8];
        return t.str();
      };
      out << std::setw(16) << line.name << std::setw(20) << triple(reference) << std::setw(20)
          << triple(ours) << std::setw(20) << triple(global) << std::fixed << std::setprecision(1)
          << rms << " / " << global_rms << "\n";
      obstacle_rms.push_back(rms);
      global_rms_all.push_back(global_rms);
      rows.push_back({{"action_line", line.name},
                      {"muscle", muscle.name},
                      {"angles_deg", angles},
                      {"atlas_mm", ours},
                      {"gait2392_mm", reference},
                      {"rms_mm", rms},
                      {"global_mm", global},
                      {"global_rms_mm", global_rms}});
    }
  }
  out << std::setprecision(1) << "median RMS difference: obstacle set "
      << wrapping::median(obstacle_rms) << " mm, global " << wrapping::median(global_rms_all)
      << " mm (" << obstacle_rms.size() << " hip lines)\n";
  std::cout << out.str();
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  const std::filesystem::path folder = out_dir != nullptr ? out_dir : ".";
  std::ofstream(folder / "wrapping.accuracy.txt") << trial_out.str() << out.str();
  std::ofstream(folder / "wrapping.accuracy.json")
      << nlohmann::json{{"whole_walk", trial},
                        {"whole_walk_volumetric", volumetric},
                        {"hip_flexion_moment_arms", rows}}
             .dump(2)
      << "\n";
}

// One path and one moment arm of every atlas action line at a pose
// (items = lines).
void BM_AtlasMomentArms(benchmark::State& state) {
  const Models& m = models();
  const int hip = *m.atlas_skeleton.coordinate_index("hip_flexion_r");
  Eigen::VectorXd q = m.atlas_skeleton.default_coordinates();
  q(hip) = 30 * kDeg;
  std::int64_t lines = 0;
  for (auto _ : state) {
    for (const mmm::atlas::Muscle& muscle : m.atlas.muscles) {
      for (const mmm::atlas::ActionLine& line : muscle.action_lines) {
        benchmark::DoNotOptimize(
            wrapping::moment_arm(m.atlas, muscle, line, m.atlas_skeleton, q, hip));
        ++lines;
      }
    }
  }
  state.SetItemsProcessed(lines);
}
BENCHMARK(BM_AtlasMomentArms)->Unit(benchmark::kMillisecond);

// Ten frames of the gluteus maximus (10K faces, the reference's worst case)
// wrapped with bone impenetrability, set-up included (items = frames).
void BM_GluteusMaximusTenFrames(benchmark::State& state) {
  motion::FusedMotion ten = atlas_walk();
  ten.times.conservativeResize(10);
  ten.coordinates.conservativeResize(10, Eigen::NoChange);
  wrapping::MuscleWrappingOptions options;
  options.muscles = {"gluteus_maximus_r"};
  options.threads = 1;
  for (auto _ : state)
    benchmark::DoNotOptimize(wrapping::wrap_muscles(models().atlas, atlas_dir(), ten, options));
  state.SetItemsProcessed(state.iterations() * 10);
}
BENCHMARK(BM_GluteusMaximusTenFrames)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return mmm::bench::run_suite(argc, argv, "mmm_bench_wrapping", write_accuracy_table);
}

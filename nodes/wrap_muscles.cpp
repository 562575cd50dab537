#include "nodes/wrap_muscles.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/atlas/structure_carriage.h"
#include "core/bounded_json.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/io/vtp_series.h"
#include "core/motion/motion_io.h"
#include "core/wrapping/muscle_wrapping.h"
#include "core/wrapping/wrapping_summary.h"
#include "nodes/name_list.h"
#include "nodes/number_text.h"

namespace mmm::nodes {
namespace {

wrapping::MuscleWrappingOptions wrapping_options_from(const workflow::NodeContext& context) {
  wrapping::MuscleWrappingOptions options;
  options.target_faces = context.integer("target_faces");
  options.bone_contacts = context.flag("bone_contacts");
  options.muscle_penetration = context.flag("muscle_penetration");
  options.muscle_contacts = context.flag("muscle_contacts");
  options.muscle_contact.weight = context.number("muscle_contact_weight");
  options.muscle_contact_rounds = static_cast<int>(context.integer("muscle_contact_rounds"));
  options.muscle_contact_settling_rounds =
      static_cast<int>(context.integer("muscle_contact_settling_rounds"));
  options.joint_muscle_contacts = context.text("muscle_contact_solver") == "joint";
  options.joint_rounds = static_cast<int>(context.integer("joint_contact_rounds"));
  options.muscle_interface_reach_mm = context.number("muscle_interface_reach_mm");
  options.intermediate_poses = static_cast<int>(context.integer("intermediate_poses"));
  options.first_frame_intermediate_poses =
      static_cast<int>(context.integer("first_frame_intermediate_poses"));
  options.muscles = split_names(context.text("muscles"));
  options.threads = static_cast<int>(context.integer("threads"));
  options.coarse_to_fine = context.flag("coarse_to_fine");
  options.routing.method = context.text("path_method") == "global"
                               ? wrapping::PathMethod::kGlobal
                               : wrapping::PathMethod::kObstacleSet;
  options.routing.global.clearance_mm = context.number("path_clearance_mm");
  options.hull_faces = context.integer("hull_faces");
  options.deformer.stiffness_length_mm = context.number("stiffness_length_mm");
  options.contacts.tolerance_mm = context.number("contact_tolerance_mm");
  options.contacts.clearance_mm = context.number("contact_clearance_mm");
  return options;
}

std::string metrics_csv(const wrapping::MuscleWrapping& wrapped) {
  std::string csv =
      "muscle,frame,time_s,volume_error_percent,max_depth_mm,vertices_inside,vertices_deeper,"
      "deepest_bone,muscle_depth_mm,muscle_vertices_deeper,deepest_muscle,"
      "smoothness_change_percent,contacts,hull_contacts,path_contacts,contact_rounds,volume_"
      "iterations,converged,ms\n";
  for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
    for (std::size_t f = 0; f < muscle.frames.size(); ++f) {
      const wrapping::MuscleFrameMetrics& m = muscle.frames[f];
      csv +=
          muscle.name + "," + std::to_string(f) + "," +
          fixed(wrapped.times(static_cast<Eigen::Index>(f)), 4) + "," +
          fixed(m.volume_error_percent, 8) + "," + fixed(m.max_depth_mm, 3) + "," +
          std::to_string(m.vertices_inside) + "," + std::to_string(m.vertices_deeper) + "," +
          m.deepest_bone + "," +
          (wrapped.muscle_penetration ? fixed(m.muscle_depth_mm, 3) : std::string()) + "," +
          (wrapped.muscle_penetration ? std::to_string(m.muscle_vertices_deeper) : std::string()) +
          "," +
          (m.deepest_muscle >= 0 ? wrapped.muscles[static_cast<std::size_t>(m.deepest_muscle)].name
                                 : std::string()) +
          "," + fixed(m.smoothness_change_percent, 2) + "," + std::to_string(m.contacts) + "," +
          std::to_string(m.hull_contacts) + "," + std::to_string(m.path_contacts) + "," +
          std::to_string(m.contact_rounds) + "," + std::to_string(m.volume_iterations) + "," +
          (m.converged ? "1" : "0") + "," + fixed(1000.0 * m.seconds, 2) + "\n";
    }
  }
  return csv;
}

std::string lines_csv(const wrapping::MuscleWrapping& wrapped) {
  std::string csv = "muscle,line,frame,time_s,length_mm";
  for (const std::string& coordinate : wrapped.moment_arm_coordinates)
    csv += ",moment_arm_" + coordinate + "_mm";
  csv += "\n";
  for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
    for (const wrapping::WrappedLine& line : muscle.lines) {
      for (std::size_t f = 0; f < line.lengths_mm.size(); ++f) {
        csv += muscle.name + "," + line.name + "," + std::to_string(f) + "," +
               fixed(wrapped.times(static_cast<Eigen::Index>(f)), 4) + "," +
               fixed(line.lengths_mm[f], 3);
        for (Eigen::Index c = 0; c < line.moment_arms_mm.cols(); ++c) {
          const double arm = line.moment_arms_mm(static_cast<Eigen::Index>(f), c);
          csv += "," + (std::isfinite(arm) ? fixed(arm, 3) : std::string());
        }
        csv += "\n";
      }
    }
  }
  return csv;
}

nlohmann::json report_of(const wrapping::MuscleWrapping& wrapped,
                         const wrapping::MuscleWrappingOptions& options) {
  nlohmann::json muscles = nlohmann::json::array();
  std::vector<double> all_ms;
  double worst_volume = 0.0;
  double worst_depth = 0.0;
  double worst_muscle_depth = 0.0;
  int unconverged = 0;
  for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
    const wrapping::MuscleWrappingSummary summary = wrapping::summarise(muscle);
    all_ms.insert(all_ms.end(), summary.ms_per_frame.begin(), summary.ms_per_frame.end());
    worst_volume = std::max(worst_volume, summary.max_abs_volume_error_percent);
    worst_depth = std::max(worst_depth, summary.max_depth_mm);
    worst_muscle_depth = std::max(worst_muscle_depth, summary.max_muscle_depth_mm);
    unconverged += summary.unconverged_frames;
    muscles.push_back(
        {{"muscle", muscle.name},
         {"faces", muscle.rest.F.rows()},
         {"rest_volume_mm3", muscle.rest_volume_mm3},
         {"rest_max_depth_mm", muscle.rest_penetration.max_depth_mm},
         {"max_abs_volume_error_percent", summary.max_abs_volume_error_percent},
         {"max_depth_mm", summary.max_depth_mm},
         {"vertex_frames_deeper_than_tolerance", summary.vertex_frames_deeper},
         {"max_depth_in_other_muscles_mm", summary.max_muscle_depth_mm},
         {"vertex_frames_deeper_in_other_muscles", summary.muscle_vertex_frames_deeper},
         {"max_smoothness_change_percent", summary.max_smoothness_change_percent},
         {"median_ms_per_frame", summary.median_ms_per_frame},
         {"setup_s", muscle.setup_seconds},
         {"separation",
          {{"overlap_at_rest_mm", muscle.rest_overlap_before_mm},
           {"overlap_after_mm", muscle.rest_overlap_after_mm},
           {"max_move_mm", muscle.separation_move_mm},
           {"interface_vertices", muscle.interface_vertices}}},
         {"hull",
          {{"faces", muscle.hull_faces},
           {"reused", muscle.hull_reused},
           {"build_s", muscle.hull_build_seconds},
           {"volume_mm3", muscle.hull_volume_mm3},
           {"vertices_outside", muscle.hull_vertices_outside},
           {"max_outside_mm", muscle.hull_max_outside_mm},
           {"max_depth_of_surface_inside_mm", muscle.hull_max_offset_mm}}}});
  }
  return {{"frames", wrapped.times.size()},
          {"muscles", muscles},
          {"threads", wrapped.threads},
          {"seconds", wrapped.seconds},
          {"median_ms_per_muscle_frame", wrapping::median(all_ms)},
          {"max_abs_volume_error_percent", worst_volume},
          {"max_depth_mm", worst_depth},
          {"muscle_penetration_measured", wrapped.muscle_penetration},
          {"max_depth_in_other_muscles_mm", worst_muscle_depth},
          {"muscle_penetration_s", wrapped.muscle_penetration_seconds},
          {"muscle_contacts", options.muscle_contacts},
          {"separation_s", wrapped.separation_seconds},
          {"separation_rounds", wrapped.separation_rounds},
          {"unconverged_muscle_frames", unconverged},
          {"targets",
           {{"volume_error_within_0.5_percent", worst_volume <= 0.5},
            {"depth_within_1_mm", worst_depth <= 1.0},
            {"whole_trial_within_60_s", wrapped.seconds <= 60.0}}},
          {"options",
           {{"target_faces", options.target_faces},
            {"bone_contacts", options.bone_contacts},
            {"intermediate_poses", options.intermediate_poses},
            {"coarse_to_fine", options.coarse_to_fine},
            {"path_method",
             options.routing.method == wrapping::PathMethod::kGlobal ? "global" : "obstacle_set"},
            {"path_clearance_mm", options.routing.global.clearance_mm},
            {"hull_faces", options.hull_faces},
            {"first_frame_intermediate_poses", options.first_frame_intermediate_poses},
            {"stiffness_length_mm", options.deformer.stiffness_length_mm},
            {"contact_tolerance_mm", options.contacts.tolerance_mm},
            {"contact_clearance_mm", options.contacts.clearance_mm},
            {"muscle_contacts", options.muscle_contacts},
            {"muscle_contact_weight", options.muscle_contact.weight},
            {"muscle_contact_rounds", options.muscle_contact_rounds},
            {"muscle_contact_settling_rounds", options.muscle_contact_settling_rounds},
            {"muscle_contact_solver", options.joint_muscle_contacts ? "joint" : "rounds"},
            {"joint_contact_rounds", options.joint_rounds},
            {"muscle_interface_reach_mm", options.muscle_interface_reach_mm}}}};
}

std::string animation_bundle(const workflow::NodeContext& context,
                             const wrapping::MuscleWrapping& wrapped, const atlas::Atlas& atlas,
                             const std::filesystem::path& atlas_dir, const std::string& bone_level,
                             int stride) {
  const std::filesystem::path folder = context.scratch_dir() / "animation";
  std::filesystem::remove_all(folder);
  mesh::VtpSeriesWriter series(folder, "wrapping");
  std::vector<mesh::IndexedMesh> bones;
  for (const std::string& name : wrapped.bone_names) {
    const atlas::Bone* bone = atlas.find_bone(name);
    const atlas::MeshLevel* chosen = &bone->meshes.front();
    for (const atlas::MeshLevel& level : bone->meshes) {
      if (level.level == bone_level) chosen = &level;
    }
    bones.push_back(mesh::read_mesh(atlas_dir / chosen->file));
  }
  const std::vector<atlas::CarriedStructure> structures =
      atlas::carried_structures(atlas, atlas_dir, bone_level);
  for (Eigen::Index k = 0; k < wrapped.times.size(); k += stride) {
    const double t = wrapped.times(k);
    const auto frame = static_cast<int>(k / stride);
    const auto f = static_cast<std::size_t>(k);
    for (std::size_t b = 0; b < bones.size(); ++b) {
      mesh::IndexedMesh moved = bones[b];
      const Eigen::Isometry3d& pose = wrapped.bone_poses[f][b];
      for (Eigen::Index v = 0; v < moved.V.rows(); ++v) {
        moved.V.row(v) = (pose * Eigen::Vector3d(moved.V.row(v).transpose())).transpose();
      }
      series.add_surface(t, frame, wrapped.bone_names[b], moved);
    }
    const auto pose_of = [&](const std::string& bone) -> std::optional<Eigen::Isometry3d> {
      const auto at = std::ranges::find(wrapped.bone_names, bone);
      if (at == wrapped.bone_names.end()) return std::nullopt;
      return wrapped.bone_poses[f][static_cast<std::size_t>(at - wrapped.bone_names.begin())];
    };
    for (const atlas::CarriedStructure& structure : structures) {
      if (auto moved = atlas::carried_surface(structure, pose_of)) {
        series.add_surface(t, frame, structure.name, *moved);
      }
    }
    mesh::Polylines lines;
    std::vector<Eigen::Vector3d> points;
    for (const wrapping::WrappedMuscle& muscle : wrapped.muscles) {
      mesh::IndexedMesh surface = muscle.rest;
      surface.V = muscle.positions[f].cast<double>();
      series.add_surface(t, frame, muscle.name, surface);
      for (const wrapping::WrappedLine& line : muscle.lines) {
        std::vector<int> indices;
        for (const Eigen::Vector3d& p : line.paths[f]) {
          indices.push_back(static_cast<int>(points.size()));
          points.push_back(p);
        }
        lines.lines.push_back(std::move(indices));
      }
    }
    lines.points.resize(static_cast<Eigen::Index>(points.size()), 3);
    for (std::size_t i = 0; i < points.size(); ++i)
      lines.points.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
    if (!lines.lines.empty()) series.add_polylines(t, frame, "action_lines", lines);
  }
  series.finish();
  return pack_directory(folder);
}

}  // namespace

workflow::NodeSpec WrapMuscles::spec() {
  using workflow::port::Atlas;
  using workflow::port::BonePoses;
  using workflow::port::File;
  using workflow::port::Report;
  const wrapping::MuscleWrappingOptions d;
  return workflow::NodeSpec{"wrap_muscles", 6,
                            "Muscle wrapping over a fused motion (energy pathway): per frame, "
                            "action lines re-routed on the "
                            "moving skeleton; each muscle surface deformed around them with its "
                            "volume held exactly (Gauss-Newton "
                            "with a Lagrange multiplier) and contacts found inside the iterations "
                            "keeping it out of the bones"}
      .input<Atlas>("atlas", "The (scaled) atlas the motion drives")
      .input<BonePoses>("motion", "Fused motion of this atlas (fuse_motion with the atlas input)")
      .optional_input<File>("hulls",
                            "Stored progressive hulls (build_hulls); a muscle whose hull is "
                            "missing or was built from another surface gets a new one")
      .param<std::int64_t>(
          "target_faces", d.target_faces,
          "Wrapping resolution: each muscle's full mesh decimated to this many faces "
          "(0: the full mesh)",
          {.min = 0, .max = 1000000})
      .param<bool>("bone_contacts", d.bone_contacts,
                   "Keep the muscles out of the bones (impenetrability)")
      .param<bool>("muscle_penetration", d.muscle_penetration,
                   "Measure how far the muscles run into each other beyond their overlap at "
                   "rest (a metric; muscle_contacts measures it too)")
      .param<bool>("muscle_contacts", d.muscle_contacts,
                   "Keep the muscles out of each other: overlaps at rest resolved once, then "
                   "per pose, two overlapping muscles meet between their surfaces (slower: "
                   "the muscles go pose by pose together)")
      .param<double>("muscle_contact_weight", d.muscle_contact.weight,
                     "How firmly a vertex in contact with another muscle is held (bone "
                     "contacts: 10000); softer keeps surfaces smoother, firmer closer",
                     {.min = 0.01, .max = 1e6})
      .param<std::int64_t>("muscle_contact_rounds", d.muscle_contact_rounds,
                           "Rounds of contacts between muscles per pose", {.min = 1, .max = 10})
      .param<std::int64_t>("muscle_contact_settling_rounds", d.muscle_contact_settling_rounds,
                           "Rounds solver: after those rounds, while a muscle is still inside "
                           "another, up to this many in which only such muscles move, pinned "
                           "onto the surface they entered as firmly as to a bone; each pose "
                           "keeps the surfaces with the shallowest entry (0: none)",
                           {.min = 0, .max = 50})
      .param_enum("muscle_contact_solver", "rounds", {"rounds", "joint"},
                  "With muscle_contacts: rounds of shared pins, each muscle solved against the "
                  "others' surfaces of the round before; or the touching muscles solved together "
                  "in one system, both sides of a contact moving at once (smoother, many times "
                  "slower)")
      .param<std::int64_t>("joint_contact_rounds", d.joint_rounds,
                           "Joint solver: solves per pose with the contacts grown",
                           {.min = 1, .max = 50})
      .param<double>("muscle_interface_reach_mm", d.muscle_interface_reach_mm,
                     "With muscle_contacts: muscles this close at rest share their motion "
                     "across the interface, so the skeleton does not drive them into each "
                     "other (0: each follows its own action lines)",
                     {.min = 0, .max = 100}, "mm")
      .param_enum("path_method", "obstacle_set", {"obstacle_set", "global"},
                  "Action-line paths: straight between the path points and wrapped over the "
                  "atlas's fitted obstacles, or the shortest path keeping clear of the bone "
                  "meshes themselves (Ceres)")
      .param<double>("path_clearance_mm", d.routing.global.clearance_mm,
                     "Global paths keep this distance from every bone", {.min = 0, .max = 20}, "mm")
      .param<bool>("coarse_to_fine", d.coarse_to_fine,
                   "Solve each muscle's progressive hull first, then its surface from there")
      .param<std::int64_t>("hull_faces", d.hull_faces, "Faces of the progressive hulls",
                           {.min = 4, .max = 1000000})
      .param<std::int64_t>("intermediate_poses", d.intermediate_poses,
                           "Interpolated variant: poses solved between consecutive frames first",
                           {.min = 0, .max = 50})
      .param<std::int64_t>("first_frame_intermediate_poses", d.first_frame_intermediate_poses,
                           "Poses solved between the rest pose and the first frame",
                           {.min = 0, .max = 100})
      .param<std::string>("muscles", "",
                          "Comma-separated muscle names; empty: every muscle of the atlas")
      .param<double>("stiffness_length_mm", d.deformer.stiffness_length_mm,
                     "How far a local push (a contact) spreads over the surface",
                     {.min = 0.5, .max = 500}, "mm")
      .param<double>("contact_tolerance_mm", d.contacts.tolerance_mm,
                     "A vertex deeper than this in a bone becomes a contact", {.min = 0, .max = 5},
                     "mm")
      .param<double>("contact_clearance_mm", d.contacts.clearance_mm,
                     "Contacts are pinned this far outside the bone", {.min = 0, .max = 5}, "mm")
      .param<std::int64_t>("threads", 0, "Worker threads (muscles in parallel); 0: the machine's",
                           {.min = 0, .max = 64})
      .param<std::int64_t>(
          "animation_stride", 5,
          "The animation holds every n-th frame (ASCII .vtp: every frame of 21 muscles "
          "over a 2 s walk is ~1.8 GB)",
          {.min = 1, .max = 1000})
      .param<std::string>("bone_level", "lod2",
                          "Atlas mesh level of the bones drawn in the animation")
      .output<File>("animation",
                    "Folder bundle of a ParaView animation (wrapping.pvd + .vtp per frame)")
      .output<File>(
          "metrics",
          "CSV per muscle and frame: volume error, penetration, contacts, smoothness, time")
      .output<File>("lines", "CSV per action line and frame: length and moment arms (hip, knee)")
      .output<File>("plot", "SVG: volume error, penetration depth, time and bending per frame")
      .output<Report>("report", "Per-muscle summaries, targets, timings");
}

void WrapMuscles::run(workflow::NodeContext& context) {
  const auto started = std::chrono::steady_clock::now();
  context.progress(0, 3, "reading the atlas and the motion");
  const std::filesystem::path atlas_dir = context.scratch_dir() / "atlas";
  unpack_directory(context.input_bytes("atlas"), atlas_dir, "input 'atlas'");
  const atlas::Atlas atlas = atlas::read_atlas(atlas_dir);
  const auto motion_bytes = context.input_bytes("motion");
  const std::string motion_text(motion_bytes.begin(), motion_bytes.end());
  nlohmann::json motion_json;
  try {
    motion_json = parse_json(motion_text);
  } catch (const nlohmann::json::exception& e) {
    throw InvalidInputError("wrap_muscles: input 'motion' is not JSON (" + std::string(e.what()) +
                            "); hint: connect fuse_motion's 'motion' output");
  }
  const motion::FusedMotion fused =
      motion::motion_from_json(motion_json, "wrap_muscles: input 'motion'");
  if (motion_json.value("model_kind", "") != "atlas") {
    throw InvalidInputError(
        "wrap_muscles: input 'motion' drives an OpenSim model, not an atlas; hint: give "
        "fuse_motion the atlas input (and the model to retarget from)");
  }
  wrapping::MuscleWrappingOptions options = wrapping_options_from(context);
  if (context.has_input("hulls")) {
    const std::filesystem::path hulls_dir = context.scratch_dir() / "hulls";
    unpack_directory(context.input_bytes("hulls"), hulls_dir, "input 'hulls'");
    options.hulls = wrapping::read_hulls(hulls_dir);
  }
  context.progress(
      1, 3,
      "wrapping " +
          std::to_string(options.muscles.empty() ? atlas.muscles.size() : options.muscles.size()) +
          " muscles over " + std::to_string(fused.num_frames()) + " frames");
  const wrapping::MuscleWrapping wrapped = wrapping::wrap_muscles(atlas, atlas_dir, fused, options);
  int hulls_built = 0;
  for (const wrapping::WrappedMuscle& muscle : wrapped.muscles)
    hulls_built += muscle.hull_faces > 0 && !muscle.hull_reused ? 1 : 0;
  if (options.coarse_to_fine && context.has_input("hulls") && hulls_built > 0) {
    context.warn(std::to_string(hulls_built) +
                 " hulls were built here: the stored ones were built from other surfaces or "
                 "face counts; hint: give build_hulls the same atlas, target_faces and hull_faces");
  }
  nlohmann::json report = report_of(wrapped, options);
  report["hulls_built_here"] = hulls_built;
  context.info("wrapped in " + fixed(wrapped.seconds, 1) + " s: max volume error " +
               fixed(report["max_abs_volume_error_percent"].get<double>(), 6) + " %, max depth " +
               fixed(report["max_depth_mm"].get<double>(), 2) + " mm");
  context.progress(2, 3, "writing the outputs");
  context.set_output("metrics", metrics_csv(wrapped));
  context.set_output("lines", lines_csv(wrapped));
  context.set_output("plot", wrapping::wrapping_metrics_svg(
                                 wrapped, "Muscle wrapping over the trial (energy pathway)"));
  context.set_output(
      "animation", animation_bundle(context, wrapped, atlas, atlas_dir, context.text("bone_level"),
                                    static_cast<int>(context.integer("animation_stride"))));
  report["node_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  context.set_output("report", report.dump(2));
  context.progress(3, 3, "done");
}

}  // namespace mmm::nodes

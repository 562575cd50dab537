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
#include "core/bounded_json.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/motion/motion_io.h"
#include "core/wrapping/muscle_wrapping.h"
#include "core/wrapping/wrapping_summary.h"
#include "nodes/name_list.h"
#include "nodes/number_text.h"
#include "nodes/wrapping_outputs.h"

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

}  // namespace

workflow::NodeSpec WrapMuscles::spec() {
  using workflow::port::Atlas;
  using workflow::port::BonePoses;
  using workflow::port::File;
  using workflow::port::Report;
  const wrapping::MuscleWrappingOptions d;
  workflow::NodeSpec spec =
      workflow::NodeSpec{"wrap_muscles", 7,
                         "Muscle wrapping over a fused motion (energy pathway): per frame, "
                         "action lines re-routed on the "
                         "moving skeleton; each muscle surface deformed around them with its "
                         "volume held exactly (Gauss-Newton "
                         "with a Lagrange multiplier) and contacts found inside the iterations "
                         "keeping it out of the bones"}
          .resources(2, 4096)
          .input<Atlas>("atlas", "The (scaled) atlas the motion drives")
          .input<BonePoses>("motion",
                            "Fused motion of this atlas (fuse_motion with the atlas input)")
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
          .param_enum(
              "muscle_contact_solver", "rounds", {"rounds", "joint"},
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
                         "Global paths keep this distance from every bone", {.min = 0, .max = 20},
                         "mm")
          .param<bool>("coarse_to_fine", d.coarse_to_fine,
                       "Solve each muscle's progressive hull first, then its surface from there")
          .param<std::int64_t>("hull_faces", d.hull_faces, "Faces of the progressive hulls",
                               {.min = 4, .max = 1000000})
          .param<std::int64_t>(
              "intermediate_poses", d.intermediate_poses,
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
                         "A vertex deeper than this in a bone becomes a contact",
                         {.min = 0, .max = 5}, "mm")
          .param<double>("contact_clearance_mm", d.contacts.clearance_mm,
                         "Contacts are pinned this far outside the bone", {.min = 0, .max = 5},
                         "mm")
          .param<std::int64_t>("threads", 0,
                               "Worker threads (muscles in parallel); 0: the machine's",
                               {.min = 0, .max = 64});
  add_wrapping_outputs(spec);
  return spec.output<Report>("report", "Per-muscle summaries, targets, timings");
}

void WrapMuscles::run(workflow::NodeContext& context) {
  const auto started = std::chrono::steady_clock::now();
  context.progress(0, 3, "reading the atlas and the motion");
  const std::filesystem::path atlas_dir = context.scratch_dir() / "atlas";
  unpack_directory(context.input_bytes("atlas"), atlas_dir, "input 'atlas'");
  const atlas::Atlas atlas = atlas::read_atlas(atlas_dir);
  const motion::FusedMotion fused = atlas_motion_input(context, "wrap_muscles");
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
  set_wrapping_outputs(context, wrapped, atlas, atlas_dir,
                       "Muscle wrapping over the trial (energy pathway)", "energy");
  report["node_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  context.set_output("report", report.dump(2));
  context.progress(3, 3, "done");
}

}  // namespace mmm::nodes

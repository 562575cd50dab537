#include "nodes/simulate_muscles.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/bounded_json.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/motion/motion_io.h"
#include "core/volumetric/lattice_io.h"
#include "core/volumetric/muscle_simulation.h"
#include "core/wrapping/wrapping_summary.h"
#include "nodes/name_list.h"
#include "nodes/number_text.h"
#include "nodes/wrapping_outputs.h"

namespace mmm::nodes {
namespace {

constexpr std::uintmax_t kMaxLatticeJsonBytes = 16 << 20;

// build_muscle_lattice's bundle: the labels, and the muscles in label order
// from lattice.json.
volumetric::LabelledLattice read_lattice_bundle(const std::filesystem::path& folder) {
  volumetric::LabelledLattice lattice = volumetric::read_lattice(folder / "muscles.lattice");
  const std::filesystem::path json_path = folder / "lattice.json";
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(json_path, error);
  if (error || !std::filesystem::is_regular_file(json_path)) {
    throw InvalidInputError(
        "simulate_muscles: input 'lattice' has no lattice.json; hint: connect "
        "build_muscle_lattice's 'lattice'");
  }
  if (size > kMaxLatticeJsonBytes) {
    throw InvalidInputError("simulate_muscles: input 'lattice': lattice.json is " +
                            std::to_string(size) + " bytes, more than a lattice's summary can be");
  }
  const std::string text = read_file_bytes(json_path, size);
  nlohmann::json summary;
  try {
    summary = parse_json(text);
  } catch (const nlohmann::json::exception& e) {
    throw InvalidInputError("simulate_muscles: input 'lattice': lattice.json is not JSON (" +
                            std::string(e.what()) + "); hint: connect build_muscle_lattice");
  }
  const nlohmann::json* rows = summary.contains("muscles") ? &summary["muscles"] : nullptr;
  if (rows == nullptr || !rows->is_array()) {
    throw InvalidInputError(
        "simulate_muscles: input 'lattice': lattice.json has no 'muscles' list; hint: connect "
        "build_muscle_lattice");
  }
  for (const nlohmann::json& row : *rows) {
    if (!row.is_object() || !row.contains("muscle") || !row["muscle"].is_string() ||
        !row.contains("segmented_mm3") || !row["segmented_mm3"].is_number() ||
        !row.contains("kept_mm3") || !row["kept_mm3"].is_number()) {
      throw InvalidInputError(
          "simulate_muscles: input 'lattice': a row of lattice.json 'muscles' lacks 'muscle', "
          "'segmented_mm3' or 'kept_mm3'");
    }
    volumetric::MuscleCells cells;
    cells.name = row["muscle"].get<std::string>();
    cells.segmented_mm3 = row["segmented_mm3"].get<double>();
    cells.kept_mm3 = row["kept_mm3"].get<double>();
    lattice.muscles.push_back(std::move(cells));
  }
  std::uint16_t highest = 0;
  for (const std::uint16_t label : lattice.label) highest = std::max(highest, label);
  if (highest > lattice.muscles.size()) {
    throw InvalidInputError("simulate_muscles: input 'lattice': the labels name " +
                            std::to_string(highest) + " muscles, lattice.json lists " +
                            std::to_string(lattice.muscles.size()));
  }
  return lattice;
}

volumetric::MuscleSimulationOptions options_from(const workflow::NodeContext& context) {
  volumetric::MuscleSimulationOptions options;
  options.lattice.spacing_mm = context.number("spacing_mm");
  options.coarsening = static_cast<int>(context.integer("coarsening"));
  const auto interfaces = volumetric::interfaces_from_name(context.text("interfaces"));
  if (!interfaces) {
    throw InvalidInputError("simulate_muscles: parameter 'interfaces' is '" +
                            context.text("interfaces") + "'; hint: shared, stick or slide");
  }
  options.interfaces = *interfaces;
  options.simulation.iterations = static_cast<int>(context.integer("rounds"));
  options.attachment_reach_mm = context.number("attachment_reach_mm");
  options.anchor_joint_clearance_mm = context.number("joint_clearance_mm");
  options.first_frame_intermediate_poses =
      static_cast<int>(context.integer("first_frame_intermediate_poses"));
  options.muscles = split_names(context.text("muscles"));
  options.muscle_penetration = context.flag("muscle_penetration");
  options.routing.method = context.text("path_method") == "global"
                               ? wrapping::PathMethod::kGlobal
                               : wrapping::PathMethod::kObstacleSet;
  options.threads = static_cast<int>(context.integer("threads"));
  return options;
}

nlohmann::json report_of(const volumetric::MuscleSimulation& simulated,
                         const volumetric::MuscleSimulationOptions& options) {
  const wrapping::MuscleWrapping& motion = simulated.motion;
  nlohmann::json muscles = nlohmann::json::array();
  double worst_volume = 0.0;
  double worst_depth = 0.0;
  double worst_muscle_depth = 0.0;
  for (std::size_t m = 0; m < motion.muscles.size(); ++m) {
    const wrapping::WrappedMuscle& muscle = motion.muscles[m];
    const wrapping::MuscleWrappingSummary summary = wrapping::summarise(muscle);
    worst_volume = std::max(worst_volume, summary.max_abs_volume_error_percent);
    worst_depth = std::max(worst_depth, summary.max_depth_mm);
    worst_muscle_depth = std::max(worst_muscle_depth, summary.max_muscle_depth_mm);
    const volumetric::MuscleCells& cells = simulated.lattice[m];
    muscles.push_back(
        {{"muscle", muscle.name},
         {"faces", muscle.rest.F.rows()},
         {"rest_volume_mm3", cells.kept_mm3},
         {"lattice_change_percent", 100.0 * cells.change()},
         {"attachment_nodes", simulated.driven_per_muscle[m]},
         {"attachment_gap_mm", simulated.attachment_gap_mm[m]},
         {"attachment_areas_left_out", simulated.attachments_left_out[m]},
         {"rest_max_depth_mm", muscle.rest_penetration.max_depth_mm},
         {"max_abs_volume_error_percent", summary.max_abs_volume_error_percent},
         {"max_depth_mm", summary.max_depth_mm},
         {"vertex_frames_deeper_than_tolerance", summary.vertex_frames_deeper},
         {"max_depth_in_other_muscles_mm", summary.max_muscle_depth_mm},
         {"vertex_frames_deeper_in_other_muscles", summary.muscle_vertex_frames_deeper},
         {"max_smoothness_change_percent", summary.max_smoothness_change_percent}});
  }
  std::vector<double> frame_ms;
  int inverted_frames = 0;
  for (const volumetric::FrameStats& frame : simulated.frames) {
    frame_ms.push_back(1000.0 * frame.seconds);
    inverted_frames += frame.inverted > 0 ? 1 : 0;
  }
  const double walk =
      simulated.setup_seconds + simulated.simulation_seconds + simulated.lines_seconds;
  return {
      {"pathway", "volumetric"},
      {"frames", motion.times.size()},
      {"muscles", muscles},
      {"threads", motion.threads},
      {"seconds", motion.seconds},
      {"model",
       {{"spacing_mm", simulated.spacing_mm},
        {"coarsening", simulated.coarsening},
        {"interfaces", std::string(volumetric::interfaces_name(options.interfaces))},
        {"interface_pairs", simulated.interface_pairs},
        {"max_interface_gap_mm", simulated.max_interface_gap_mm},
        {"max_interface_slide_mm", simulated.max_interface_slide_mm},
        {"element_nodes", simulated.element_nodes},
        {"elements", simulated.elements},
        {"output_nodes", simulated.output_nodes},
        {"attachment_nodes", simulated.driven_nodes},
        {"element_nodes_in_bones", simulated.anchored_element_nodes},
        {"rest_surface_nodes_moved_out_of_bones", simulated.rest_moved_nodes},
        {"rest_largest_move_out_of_bones_mm", simulated.rest_moved_out_of_bones_mm},
        {"nodes_checked_against_bones", simulated.checked_nodes}}},
      {"time",
       {{"setup_s", simulated.setup_seconds},
        {"simulation_s", simulated.simulation_seconds},
        {"median_ms_per_frame", wrapping::median(frame_ms)},
        {"lines_s", simulated.lines_seconds},
        {"measurements_s", simulated.measure_seconds},
        {"whole_walk_s", walk}}},
      {"max_abs_volume_error_percent", worst_volume},
      {"max_depth_mm", worst_depth},
      {"muscle_penetration_measured", motion.muscle_penetration},
      {"max_depth_in_other_muscles_mm", worst_muscle_depth},
      {"muscle_penetration_s", motion.muscle_penetration_seconds},
      {"max_inverted_elements", simulated.max_inverted},
      {"frames_with_inverted_elements", inverted_frames},
      {"targets",
       {{"volume_error_within_1_percent", worst_volume <= 1.0},
        {"depth_within_0.5_mm", worst_depth <= 0.5},
        {"depth_in_other_muscles_within_0.5_mm",
         motion.muscle_penetration && worst_muscle_depth <= 0.5},
        {"no_inverted_element", simulated.max_inverted == 0},
        {"whole_trial_within_60_s", walk <= 60.0}}},
      {"options",
       {{"spacing_mm", options.lattice.spacing_mm},
        {"coarsening", options.coarsening},
        {"rounds", options.simulation.iterations},
        {"attachment_reach_mm", options.attachment_reach_mm},
        {"joint_clearance_mm", options.anchor_joint_clearance_mm},
        {"first_frame_intermediate_poses", options.first_frame_intermediate_poses},
        {"path_method",
         options.routing.method == wrapping::PathMethod::kGlobal ? "global" : "obstacle_set"}}}};
}

}  // namespace

workflow::NodeSpec SimulateMuscles::spec() {
  using workflow::port::Atlas;
  using workflow::port::BonePoses;
  using workflow::port::File;
  using workflow::port::Report;
  const volumetric::MuscleSimulationOptions d;
  workflow::NodeSpec spec =
      workflow::NodeSpec{"simulate_muscles", 2,
                         "Muscle wrapping over a fused motion (volumetric pathway): every muscle "
                         "in one conforming tetrahedral model, touching muscles sharing their "
                         "interface, moved by the bones frame by frame (projective dynamics), "
                         "each muscle's volume restored exactly, attachments following their "
                         "bones, surfaces kept out of the bones"}
          .resources(2, 6144)
          .input<Atlas>("atlas", "The (scaled) atlas the motion drives")
          .input<BonePoses>("motion",
                            "Fused motion of this atlas (fuse_motion with the atlas input)")
          .optional_input<File>(
              "lattice",
              "The model at rest (build_muscle_lattice on the same atlas); without "
              "it the lattice is built here")
          .param<double>("spacing_mm", d.lattice.spacing_mm,
                         "Without a lattice input: the lattice's cell edge",
                         {.min = 0.5, .max = 20.0}, "mm")
          .param<std::int64_t>(
              "coarsening", d.coarsening,
              "Simulated elements are this many lattice cells across; the surfaces "
              "keep the lattice's detail (1: every cell simulated)",
              {.min = 1, .max = 8})
          .param_enum("interfaces", "shared", {"shared", "stick", "slide"},
                      "Touching muscles: one body sharing its interface nodes (shared), or "
                      "separate bodies whose interface nodes are tied (stick) or may slide "
                      "along each other (slide: pairs fixed at rest; over a walk they go "
                      "stale, see docs/pipeline/volumetric.md)")
          .param<std::int64_t>("rounds", d.simulation.iterations, "Local-global rounds per frame",
                               {.min = 1, .max = 100})
          .param<double>(
              "attachment_reach_mm", d.attachment_reach_mm,
              "A muscle's surface nodes this close to one of its attachment areas follow "
              "that bone",
              {.min = 0.1, .max = 50.0}, "mm")
          .param<double>("joint_clearance_mm", d.anchor_joint_clearance_mm,
                         "Elements reaching into a bone follow it, except within this distance of "
                         "a bone that moves otherwise (a joint), where the tissue is left to slide "
                         "(0: everywhere)",
                         {.min = 0.0, .max = 50.0}, "mm")
          .param<std::int64_t>("first_frame_intermediate_poses", d.first_frame_intermediate_poses,
                               "Steps between the rest pose and the first frame",
                               {.min = 0, .max = 100})
          .param<std::string>(
              "muscles", "",
              "Comma-separated muscle names; empty: every muscle of the lattice (or "
              "the atlas)")
          .param<bool>("muscle_penetration", d.muscle_penetration,
                       "Measure how far the muscles' surfaces run into each other (a metric)")
          .param_enum("path_method", "obstacle_set", {"obstacle_set", "global"},
                      "Action-line paths: over the atlas's fitted obstacles, or the shortest path "
                      "keeping clear of the bone meshes (Ceres)")
          .param<std::int64_t>("threads", 0, "Worker threads; 0: the machine's",
                               {.min = 0, .max = 64});
  add_wrapping_outputs(spec);
  return spec.output<Report>("report", "Per-muscle summaries, the model, timings, targets");
}

void SimulateMuscles::run(workflow::NodeContext& context) {
  const auto started = std::chrono::steady_clock::now();
  context.progress(0, 3, "reading the atlas and the motion");
  const std::filesystem::path atlas_dir = context.scratch_dir() / "atlas";
  unpack_directory(context.input_bytes("atlas"), atlas_dir, "input 'atlas'");
  const atlas::Atlas atlas = atlas::read_atlas(atlas_dir);
  const motion::FusedMotion fused = atlas_motion_input(context, "simulate_muscles");
  std::optional<volumetric::LabelledLattice> lattice;
  if (context.has_input("lattice")) {
    const std::filesystem::path folder = context.scratch_dir() / "lattice";
    unpack_directory(context.input_bytes("lattice"), folder, "input 'lattice'");
    lattice = read_lattice_bundle(folder);
  }
  const volumetric::MuscleSimulationOptions options = options_from(context);
  context.progress(1, 3, "simulating over " + std::to_string(fused.num_frames()) + " frames");
  const volumetric::MuscleSimulation simulated =
      volumetric::simulate_muscles(atlas, atlas_dir, fused, options, lattice ? &*lattice : nullptr);
  nlohmann::json report = report_of(simulated, options);
  if (simulated.max_inverted > 0) {
    context.warn(std::to_string(report["frames_with_inverted_elements"].get<int>()) +
                 " frame(s) have inverted elements (at worst " +
                 std::to_string(simulated.max_inverted) +
                 "); hint: more rounds or first_frame_intermediate_poses");
  }
  context.info("simulated in " + fixed(simulated.motion.seconds, 1) + " s: max volume error " +
               fixed(report["max_abs_volume_error_percent"].get<double>(), 4) +
               " %, max depth in bone " + fixed(report["max_depth_mm"].get<double>(), 2) +
               " mm, in other muscles " +
               fixed(report["max_depth_in_other_muscles_mm"].get<double>(), 2) + " mm");
  context.progress(2, 3, "writing the outputs");
  set_wrapping_outputs(context, simulated.motion, atlas, atlas_dir,
                       "Muscle wrapping over the trial (volumetric pathway)", "volumetric");
  report["node_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  context.set_output("report", report.dump(2));
  context.progress(3, 3, "done");
}

}  // namespace mmm::nodes

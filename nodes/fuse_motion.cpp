#include "nodes/fuse_motion.h"

#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

#include "core/atlas/atlas_io.h"
#include "core/atlas/structure_carriage.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/io/vtp_series.h"
#include "core/motion/marker_mapping.h"
#include "core/motion/marker_placement.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/motion_io.h"
#include "core/motion/motion_plot.h"
#include "core/motion/motion_points.h"
#include "core/motion/motion_tables.h"
#include "core/motion/retarget.h"
#include "core/motion/skeleton.h"
#include "core/opensim/mot.h"
#include "core/opensim/osim_model.h"
#include "core/opensim/trc.h"

namespace mmm::nodes {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

motion::MotionFusionOptions fusion_options_from(const workflow::NodeContext& context) {
  motion::MotionFusionOptions options;
  const double start = context.number("start_time");
  const double end = context.number("end_time");
  if (start > 0) options.start_time = start;
  if (end >= 0) options.end_time = end;
  const std::string& filter = context.text("filter");
  options.filter.mode = filter == "none"      ? motion::FilterMode::kNone
                        : filter == "forward" ? motion::FilterMode::kForward
                                              : motion::FilterMode::kSmoother;
  options.filter.angular_acceleration_sd = context.number("angular_acceleration_sd");
  options.filter.linear_acceleration_sd = context.number("linear_acceleration_sd");
  options.filter.marker_noise_mm = context.number("marker_noise_mm");
  options.fit.respect_limits = context.flag("joint_limits");
  return options;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

nlohmann::json fit_summary(const motion::FusedMotion& fused) {
  nlohmann::json markers = nlohmann::json::array();
  for (Eigen::Index m = 0; m < fused.marker_errors.cols(); ++m) {
    double squares = 0.0;
    double worst = 0.0;
    int present = 0;
    for (Eigen::Index k = 0; k < fused.marker_errors.rows(); ++k) {
      const double e = fused.marker_errors(k, m);
      if (!std::isfinite(e)) continue;
      squares += e * e;
      worst = std::max(worst, e);
      ++present;
    }
    markers.push_back({{"marker", fused.marker_names[static_cast<std::size_t>(m)]},
                       {"frames_present", present},
                       {"rms_mm", present > 0 ? std::sqrt(squares / present) : 0.0},
                       {"max_mm", worst}});
  }
  nlohmann::json coordinates = nlohmann::json::array();
  for (std::size_t c = 0; c < fused.coordinate_names.size(); ++c) {
    const Eigen::VectorXd column = fused.coordinates.col(static_cast<Eigen::Index>(c));
    const bool angle = fused.coordinate_units[c] == motion::CoordinateUnit::kAngle;
    const double unit = angle ? kDeg : 1.0;
    coordinates.push_back({{"coordinate", fused.coordinate_names[c]},
                           {"unit", angle ? "deg" : "mm"},
                           {"min", unit * column.minCoeff()},
                           {"max", unit * column.maxCoeff()}});
  }
  nlohmann::json bodies = nlohmann::json::array();
  for (const motion::BodyRegistrationSummary& r : fused.registrations) {
    bodies.push_back(
        {{"body", r.body},
         {"frames_registered", r.frames_registered},
         {"cluster_rms_mm", r.cluster_rms_mm},
         {"joint_gap_mm", std::isfinite(r.joint_gap_mm) ? nlohmann::json(r.joint_gap_mm)
                                                        : nlohmann::json(nullptr)}});
  }
  std::vector<double> per_frame(fused.rms_mm.data(), fused.rms_mm.data() + fused.rms_mm.size());
  std::vector<double> seconds(fused.fit_seconds.data(),
                              fused.fit_seconds.data() + fused.fit_seconds.size());
  return {{"frames", fused.num_frames()},
          {"time_range_s", {fused.times(0), fused.times(fused.num_frames() - 1)}},
          {"marker_rms_mm", fused.overall_rms_mm()},
          {"marker_rms_per_frame_median_mm", median(per_frame)},
          {"marker_rms_per_frame_max_mm", fused.rms_mm.maxCoeff()},
          {"markers", markers},
          {"coordinates", coordinates},
          {"free_body_registration", bodies},
          {"fit_ms_per_frame_median", 1000.0 * median(seconds)},
          {"notes", fused.notes}};
}

// The bundle of the animation: bones, cartilages and ligaments of the atlas
// at `level`, the stick
// figure, the action lines, per frame.
std::string animation_bundle(const workflow::NodeContext& context, const motion::Skeleton& skeleton,
                             const motion::FusedMotion& fused,
                             const motion::PointTrajectories& points, const atlas::Atlas* atlas,
                             const std::filesystem::path& atlas_dir, const std::string& level) {
  const std::filesystem::path folder = context.scratch_dir() / "animation";
  std::filesystem::remove_all(folder);
  mesh::VtpSeriesWriter series(folder, "motion");
  std::vector<std::pair<int, mesh::IndexedMesh>> bones;
  std::vector<atlas::CarriedStructure> structures;
  if (atlas != nullptr) structures = atlas::carried_structures(*atlas, atlas_dir, level);
  if (atlas != nullptr) {
    for (const atlas::Bone& bone : atlas->bones) {
      const atlas::MeshLevel* chosen = &bone.meshes.front();
      for (const atlas::MeshLevel& m : bone.meshes) {
        if (m.level == level) chosen = &m;
      }
      bones.emplace_back(*skeleton.body_index(bone.name),
                         mesh::read_mesh(atlas_dir / chosen->file));
    }
  }
  for (Eigen::Index k = 0; k < fused.num_frames(); ++k) {
    const double t = fused.times(k);
    const auto frame = static_cast<int>(k);
    const std::vector<Eigen::Isometry3d>& poses = fused.poses[static_cast<std::size_t>(k)];
    for (const auto& [body, rest] : bones) {
      mesh::IndexedMesh moved = rest;
      const Eigen::Isometry3d& pose = poses[static_cast<std::size_t>(body)];
      for (Eigen::Index v = 0; v < moved.V.rows(); ++v) {
        moved.V.row(v) = (pose * Eigen::Vector3d(moved.V.row(v).transpose())).transpose();
      }
      series.add_surface(t, frame, skeleton.bodies[static_cast<std::size_t>(body)].name, moved);
    }
    const auto pose_of = [&](const std::string& bone) -> std::optional<Eigen::Isometry3d> {
      const auto body = skeleton.body_index(bone);
      if (!body) return std::nullopt;
      return poses[static_cast<std::size_t>(*body)];
    };
    for (const atlas::CarriedStructure& structure : structures) {
      if (auto moved = atlas::carried_surface(structure, pose_of)) {
        series.add_surface(t, frame, structure.name, *moved);
      }
    }
    const motion::StickFigure stick = motion::stick_figure(skeleton, poses);
    if (!stick.segments.empty()) {
      mesh::Polylines lines;
      lines.points = stick.points;
      for (const auto& [a, b] : stick.segments) lines.lines.push_back({a, b});
      series.add_polylines(t, frame, "skeleton", lines);
    }
    {  // action lines exist only for an atlas; markers have no path points
      // Action lines: the active points of each line, in order.
      mesh::Polylines lines;
      std::vector<Eigen::Vector3d> xyz;
      std::string current;
      std::vector<int> line;
      const auto flush = [&] {
        if (line.size() >= 2) lines.lines.push_back(line);
        line.clear();
      };
      for (std::size_t i = 0; i < points.points.size(); ++i) {
        const motion::TrackedPoint& p = points.points[i];
        if (p.kind != "path_point") continue;
        if (p.element != current) {
          flush();
          current = p.element;
        }
        if (points.active(k, static_cast<Eigen::Index>(i)) == 0) continue;
        line.push_back(static_cast<int>(xyz.size()));
        xyz.emplace_back(
            points.positions.block<1, 3>(k, 3 * static_cast<Eigen::Index>(i)).transpose());
      }
      flush();
      if (!lines.lines.empty()) {
        lines.points.resize(static_cast<Eigen::Index>(xyz.size()), 3);
        for (std::size_t i = 0; i < xyz.size(); ++i) {
          lines.points.row(static_cast<Eigen::Index>(i)) = xyz[i].transpose();
        }
        series.add_polylines(t, frame, "action_lines", lines);
      }
    }
  }
  series.finish();
  return pack_directory(folder);
}

}  // namespace

workflow::NodeSpec FuseMotion::spec() {
  using workflow::port::Atlas;
  using workflow::port::BonePoses;
  using workflow::port::File;
  using workflow::port::Report;
  const motion::MotionFusionOptions d;
  return workflow::NodeSpec{
      "fuse_motion", 1,
      "Drive a model with a marker trial: Kabsch per body, Ceres kinematic-chain fit, Kalman "
      "filter with RTS smoother and joint limits; optional marker placement from a static trial "
      "and retargeting from the trial subject's model to the patient's atlas"}
      .input<File>("trial", "Marker trial (.trc); gaps and NaN frames allowed")
      .optional_input<Atlas>("atlas", "The patient's (scaled) atlas to drive")
      .optional_input<File>("model",
                            "OpenSim model (.osim): driven itself, or with an atlas the trial "
                            "subject's model the motion is fitted to and retargeted from")
      .optional_input<File>("mapping",
                            "Marker mapping (YAML, schemas/motion/); default: gait2392's with "
                            "OpenSim's IK weights")
      .optional_input<File>("static_trial",
                            "Standing trial (.trc): the fitted model's markers are placed where "
                            "the subject wore them")
      .optional_input<File>("reference", "Joint angles to compare with (.mot, e.g. OpenSim IK)")
      .param<double>("start_time", 0.0, "First time fused (s); 0: the trial's start", {.min = 0},
                     "s")
      .param<double>("end_time", -1.0, "Last time fused (s); negative: the trial's end", {}, "s")
      .param_enum("filter", "smoother", {"none", "forward", "smoother"},
                  "Temporal filter: none (per-frame IK as OpenSim), forward Kalman, or Kalman "
                  "with a Rauch-Tung-Striebel smoother (no lag)")
      .param<double>("angular_acceleration_sd", d.filter.angular_acceleration_sd,
                     "Filter process noise of angles (white acceleration, rad/s^2 per sqrt(Hz))",
                     {.min = 1e-3, .max = 1e6})
      .param<double>("linear_acceleration_sd", d.filter.linear_acceleration_sd,
                     "Filter process noise of translations (mm/s^2 per sqrt(Hz))",
                     {.min = 1e-3, .max = 1e8})
      .param<double>("marker_noise_mm", d.filter.marker_noise_mm,
                     "Noise of a weight-1 marker, as the filter assumes it",
                     {.min = 0.01, .max = 100}, "mm")
      .param<bool>("joint_limits", true, "Keep clamped coordinates inside their ranges")
      .param<bool>("keep_ground_contact", true,
                   "Retargeting: shift the patient vertically so that its feet reach the ground "
                   "as low as the subject's")
      .param<std::string>("mesh_level", "lod1", "Atlas mesh level drawn in the animation")
      .output<BonePoses>("motion", "Per-frame coordinates, body poses and marker errors")
      .output<File>("angles", "Joint angles (.mot; deg and m, OpenSim's conventions)")
      .output<File>("points",
                    "CSV of every landmark, attachment area, action-line point and marker per "
                    "frame")
      .output<Report>("report", "Markers, residuals, filter, retargeting, reference comparison")
      .output<File>("plot", "SVG of the joint angles over time")
      .output<File>("animation", "Folder bundle of a ParaView animation (.pvd + .vtp per frame)");
}

void FuseMotion::run(workflow::NodeContext& context) {
  const auto started = std::chrono::steady_clock::now();
  const motion::MotionFusionOptions options = fusion_options_from(context);
  context.progress(0, 5, "reading the inputs");
  const opensim::MarkerTrajectories trial =
      opensim::parse_trc(context.input_bytes("trial"), context.input("trial").path);
  for (const std::string& warning : trial.warnings) context.warn("trial: " + warning);
  const motion::MarkerMapping mapping =
      context.has_input("mapping") ? motion::parse_marker_mapping(context.input_bytes("mapping"),
                                                                  context.input("mapping").path)
                                   : motion::gait2392_marker_mapping();
  if (!context.has_input("atlas") && !context.has_input("model")) {
    throw InvalidInputError(
        "fuse_motion: nothing to drive; connect 'atlas' (a patient's atlas) or 'model' (an "
        "OpenSim .osim), or both to retarget from the model to the atlas");
  }
  std::optional<atlas::Atlas> patient;
  const std::filesystem::path atlas_dir = context.scratch_dir() / "atlas";
  if (context.has_input("atlas")) {
    unpack_directory(context.input_bytes("atlas"), atlas_dir, "input 'atlas'");
    patient = atlas::read_atlas(atlas_dir);
  }
  std::optional<motion::Skeleton> subject;
  std::string subject_name;
  if (context.has_input("model")) {
    const opensim::OsimModel model =
        opensim::parse_osim(context.input_bytes("model"), context.input("model").path);
    subject = motion::skeleton_from_osim(model);
    subject_name = model.name;
  }
  const motion::Skeleton target = patient ? motion::skeleton_from_atlas(*patient) : *subject;
  const std::string target_name = patient ? patient->name : subject_name;
  motion::Skeleton fitted = subject ? *subject : target;

  nlohmann::json report;
  report["model"] = {{"driven", target_name},
                     {"kind", patient ? "atlas" : "osim"},
                     {"fitted_to_trial", subject ? subject_name : target_name},
                     {"retargeted", patient && subject}};
  report["mapping"] = mapping.name.empty() ? mapping.source.string() : mapping.name;
  if (context.has_input("static_trial")) {
    context.progress(1, 5, "placing markers from the static trial");
    const opensim::MarkerTrajectories standing =
        opensim::parse_trc(context.input_bytes("static_trial"), context.input("static_trial").path);
    const motion::MarkerPlacement placed = motion::place_markers(fitted, standing, mapping);
    fitted = placed.skeleton;
    nlohmann::json moved = nlohmann::json::array();
    for (const motion::PlacedMarker& m : placed.markers) {
      moved.push_back({{"marker", m.name}, {"moved", m.moved}, {"distance_mm", m.moved_mm}});
    }
    report["marker_placement"] = {{"frames_averaged", placed.frames_averaged},
                                  {"rms_before_mm", placed.rms_before_mm},
                                  {"rms_after_mm", placed.rms_after_mm},
                                  {"markers", moved},
                                  {"notes", placed.notes}};
    context.info("markers placed: static pose RMS " + std::to_string(placed.rms_before_mm) +
                 " mm -> " + std::to_string(placed.rms_after_mm) + " mm");
  }
  context.progress(2, 5, "fusing the trial");
  const motion::FusedMotion fit = motion::fuse_motion(fitted, trial, mapping, options);
  for (const std::string& note : fit.notes) context.warn(note);
  report["tracking"] = {{"markers", fit.marker_names},
                        {"mapped_but_not_in_trial", fit.setup.not_in_trial},
                        {"mapped_but_not_on_model", fit.setup.not_on_model},
                        {"unknown_coordinates", fit.setup.unknown_coordinates},
                        {"trial_markers_unused", fit.setup.trial_unused}};
  report["filter"] = context.text("filter");
  report["fit"] = fit_summary(fit);
  context.info("fitted " + std::to_string(fit.num_frames()) + " frames, marker RMS " +
               std::to_string(fit.overall_rms_mm()) + " mm");

  motion::FusedMotion result = fit;
  if (patient && subject) {
    context.progress(3, 5, "retargeting to the patient");
    motion::RetargetOptions retarget_options;
    retarget_options.keep_ground_contact = context.flag("keep_ground_contact");
    motion::Retargeted retargeted =
        motion::retarget_motion(fit, fitted, target, trial, mapping, retarget_options);
    report["retargeting"] = {
        {"leg_length_ratio", retargeted.leg_length_ratio},
        {"vertical_shift_mm", retargeted.vertical_shift_mm},
        {"transferred", retargeted.transferred},
        {"defaulted", retargeted.defaulted},
        {"subject_foot_height_mm", {retargeted.source_foot_min_mm, retargeted.source_foot_max_mm}},
        {"patient_foot_height_mm", {retargeted.target_foot_min_mm, retargeted.target_foot_max_mm}},
        {"patient_marker_rms_mm", retargeted.motion.overall_rms_mm()},
        {"patient_marker_rms_aligned_mm", retargeted.aligned_marker_rms_mm},
        {"notes", retargeted.notes}};
    context.info("retargeted: leg length ratio " + std::to_string(retargeted.leg_length_ratio) +
                 ", patient markers vs trial RMS " +
                 std::to_string(retargeted.motion.overall_rms_mm()) + " mm");
    result = std::move(retargeted.motion);
  }

  std::optional<opensim::StorageTable> reference;
  if (context.has_input("reference")) {
    reference =
        opensim::parse_mot(context.input_bytes("reference"), context.input("reference").path);
    nlohmann::json table = nlohmann::json::array();
    for (const motion::CoordinateDifference& d : motion::compare_coordinates(fit, *reference)) {
      table.push_back({{"coordinate", d.coordinate},
                       {"unit", d.angle ? "deg" : "mm"},
                       {"samples", d.samples},
                       {"rms", d.rms},
                       {"mean", d.mean},
                       {"max_abs", d.max_abs}});
    }
    report["reference_comparison"] = table;
  }

  context.progress(4, 5, "writing the outputs");
  context.set_output(
      "motion", motion::motion_to_json(result, target_name, patient ? "atlas" : "osim").dump());
  const std::filesystem::path mot = context.scratch_dir() / "angles.mot";
  opensim::write_mot(motion::coordinate_table(result, target_name + "_ik"), mot);
  context.set_output_file("angles", mot);
  const motion::PointTrajectories points =
      patient ? motion::atlas_point_trajectories(*patient, target, result)
              : motion::marker_trajectories(target, result);
  context.set_output("points", motion::point_trajectories_csv(points, result));
  motion::AnglePlotOptions plot_options;
  plot_options.title = "Joint angles: " + target_name + (reference ? " vs reference" : "");
  context.set_output("plot",
                     motion::joint_angle_svg(fit, reference ? &*reference : nullptr, plot_options));
  context.set_output(
      "animation", animation_bundle(context, target, result, points, patient ? &*patient : nullptr,
                                    atlas_dir, context.text("mesh_level")));
  report["seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  context.set_output("report", report.dump(2));
  context.progress(5, 5, "done");
}

}  // namespace mmm::nodes

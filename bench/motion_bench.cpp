// Motion fusion (issue 7): our inverse kinematics of subject01's walk
// against OpenSim's own (reference/subject01_walk1_ik.mot) over 0.5-2.5 s,
// with OpenSim's scaled model of the subject and with our own scaling of the
// default atlas; and the speed of the kinematic fit per frame (Google
// Benchmark, medians over repetitions).
//
// The accuracy table goes to stdout and, as JSON, to
// $MMM_BENCH_OUT_DIR/motion.accuracy.json (bench/table.py folds it into
// build/bench/motion.json); the joint-angle plot to
// $MMM_BENCH_OUT_DIR/motion_angles.svg.

#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_main.h"
#include "core/atlas/atlas_io.h"
#include "core/atlas/atlas_meshes.h"
#include "core/fit/rigid_fit.h"
#include "core/landmarks/static_trial_landmarks.h"
#include "core/motion/chain_fit.h"
#include "core/motion/marker_mapping.h"
#include "core/motion/marker_placement.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/motion_plot.h"
#include "core/motion/motion_tables.h"
#include "core/motion/skeleton.h"
#include "core/opensim/mot.h"
#include "core/opensim/osim_model.h"
#include "core/opensim/trc.h"
#include "core/plot/svg_plot.h"
#include "core/scaling/atlas_scaling.h"

namespace {

namespace motion = mmm::motion;

std::filesystem::path pipelines() {
  return std::filesystem::path(MMM_DATA_DIR) / "gait2392" / "Pipelines";
}

struct Subject {
  motion::Skeleton skeleton;
  mmm::opensim::MarkerTrajectories walk;
  mmm::opensim::StorageTable reference;
};

const Subject& subject() {
  static const Subject data = [] {
    Subject s;
    s.skeleton = motion::skeleton_from_osim(
        mmm::opensim::read_osim(pipelines() / "reference" / "subject01_simbody.osim"));
    s.walk = mmm::opensim::read_trc(pipelines() / "subject01_walk1.trc");
    s.reference = mmm::opensim::read_mot(pipelines() / "reference" / "subject01_walk1_ik.mot");
    return s;
  }();
  return data;
}

motion::MotionFusionOptions walk_options(motion::FilterMode mode) {
  motion::MotionFusionOptions options;
  options.start_time = 0.5;
  options.end_time = 2.5;
  options.filter.mode = mode;
  return options;
}

std::string fixed(double value, int decimals) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(decimals) << value;
  return text.str();
}

const std::vector<std::pair<std::string, double>> kLimits = {
    {"hip_flexion_r", 2.0},   {"hip_adduction_r", 3.0}, {"hip_rotation_r", 3.0},
    {"knee_angle_r", 2.0},    {"ankle_angle_r", 2.0},   {"hip_flexion_l", 2.0},
    {"hip_adduction_l", 3.0}, {"hip_rotation_l", 3.0},  {"knee_angle_l", 2.0},
    {"ankle_angle_l", 2.0}};

// The tracked markers' measured positions in one fused frame.
Eigen::MatrixX3d targets_of(const motion::FusedMotion& fused, Eigen::Index k) {
  const mmm::opensim::MarkerTrajectories& walk = subject().walk;
  Eigen::MatrixX3d targets(static_cast<Eigen::Index>(fused.setup.markers.size()), 3);
  for (std::size_t i = 0; i < fused.setup.markers.size(); ++i) {
    targets.row(static_cast<Eigen::Index>(i)) =
        walk.unit_to_mm *
        walk.position(fused.trial_frames[static_cast<std::size_t>(k)], fused.setup.markers[i].trial)
            .transpose();
  }
  return targets;
}

// Marker errors of OpenSim's own IK solution on the same model and markers
// (its coordinates interpolated at our frame times): #frames by #markers.
Eigen::MatrixXd opensim_marker_errors(const motion::FusedMotion& fused) {
  const Subject& s = subject();
  motion::ChainFitter evaluator(s.skeleton, fused.setup);
  Eigen::MatrixXd errors(fused.num_frames(), static_cast<Eigen::Index>(fused.setup.markers.size()));
  for (Eigen::Index k = 0; k < fused.num_frames(); ++k) {
    const Eigen::RowVectorXd row = s.reference.interpolate(fused.times(k));
    Eigen::VectorXd q = s.skeleton.default_coordinates();
    for (int c = 0; c < s.skeleton.num_coordinates(); ++c) {
      const motion::SkeletonCoordinate& coordinate =
          s.skeleton.coordinates[static_cast<std::size_t>(c)];
      if (const auto column = s.reference.column_index(coordinate.name)) {
        q(c) = coordinate.unit == motion::CoordinateUnit::kAngle
                   ? row(*column) * 3.14159265358979 / 180.0
                   : row(*column) * 1000.0;
      }
    }
    errors.row(k) = evaluator.evaluate(targets_of(fused, k), q).marker_errors.transpose();
  }
  return errors;
}

// RMS over the markers whose body is (not) the torso, and over all.
struct MarkerRms {
  double all = 0, lower_body = 0, upper_body = 0;
  double weighted = 0;  // sqrt(sum w e^2 / sum w): the objective's own measure
};
MarkerRms marker_rms(const motion::FusedMotion& fused, const Eigen::MatrixXd& errors) {
  const Subject& s = subject();
  std::array<double, 3> sums = {0, 0, 0};
  std::array<double, 3> counts = {0, 0, 0};
  double weighted = 0;
  double weights = 0;
  for (Eigen::Index m = 0; m < errors.cols(); ++m) {
    const int body = s.skeleton
                         .markers[static_cast<std::size_t>(
                             fused.setup.markers[static_cast<std::size_t>(m)].model)]
                         .body;
    const bool torso = s.skeleton.bodies[static_cast<std::size_t>(body)].name == "torso";
    for (Eigen::Index k = 0; k < errors.rows(); ++k) {
      const double e = errors(k, m);
      if (!std::isfinite(e)) continue;
      const double w = fused.setup.markers[static_cast<std::size_t>(m)].weight;
      weighted += w * e * e;
      weights += w;
      for (const std::size_t g : {std::size_t{0}, std::size_t{torso ? 2U : 1U}}) {
        sums.at(g) += e * e;
        counts.at(g) += 1;
      }
    }
  }
  const auto rms = [&](std::size_t g) {
    return counts.at(g) > 0 ? std::sqrt(sums.at(g) / counts.at(g)) : 0.0;
  };
  return {rms(0), rms(1), rms(2), weights > 0 ? std::sqrt(weighted / weights) : 0.0};
}

nlohmann::json accuracy_table(std::ostream& out) {
  const Subject& s = subject();
  const motion::MarkerMapping mapping = motion::gait2392_marker_mapping();
  const std::vector<std::pair<std::string, motion::FilterMode>> modes = {
      {"none", motion::FilterMode::kNone},
      {"forward", motion::FilterMode::kForward},
      {"smoother", motion::FilterMode::kSmoother}};
  std::map<std::string, std::map<std::string, motion::CoordinateDifference>> by_mode;
  std::map<std::string, MarkerRms> rms;
  std::optional<motion::FusedMotion> smoothed;
  MarkerRms theirs;
  for (const auto& [name, mode] : modes) {
    motion::FusedMotion fused =
        motion::fuse_motion(s.skeleton, s.walk, mapping, walk_options(mode));
    for (const motion::CoordinateDifference& d : motion::compare_coordinates(fused, s.reference)) {
      by_mode[name][d.coordinate] = d;
    }
    rms[name] = marker_rms(fused, fused.marker_errors);
    if (mode == motion::FilterMode::kNone) theirs = marker_rms(fused, opensim_marker_errors(fused));
    if (mode == motion::FilterMode::kSmoother) smoothed = std::move(fused);
  }
  out << "\nours vs OpenSim IK: subject01_walk1, 0.5-2.5 s (" << smoothed->num_frames()
      << " frames), OpenSim's scaled model, gait2392 IK weights;\nRMS difference per "
         "coordinate (deg; pelvis translations mm), per filter of ours\n";
  out << std::left << std::setw(20) << "coordinate";
  for (const auto& [name, mode] : modes) out << " " << std::setw(10) << name;
  out << " limit\n";
  nlohmann::json coordinates = nlohmann::json::array();
  for (const auto& [coordinate, difference] : by_mode["none"]) {
    std::string limit;
    for (const auto& [c, l] : kLimits) {
      if (c == coordinate) limit = "<= " + fixed(l, 0);
    }
    out << std::setw(20) << coordinate;
    nlohmann::json row = {{"coordinate", coordinate},
                          {"limit", limit},
                          {"unit", difference.angle ? "deg" : "mm"},
                          {"opensim_range", difference.reference_range}};
    for (const auto& [name, mode] : modes) {
      out << " " << std::setw(10) << fixed(by_mode[name][coordinate].rms, 3);
      row["rms_" + name] = by_mode[name][coordinate].rms;
      row["max_" + name] = by_mode[name][coordinate].max_abs;
    }
    out << " " << limit << "\n";
    coordinates.push_back(row);
  }
  nlohmann::json markers = nlohmann::json::object();
  const auto marker_row = [&](const char* label, double MarkerRms::*field) {
    out << std::setw(20) << label;
    for (const auto& [name, mode] : modes) {
      out << " " << std::setw(10) << fixed(rms[name].*field, 2);
      markers[label][name] = rms[name].*field;
    }
    out << " OpenSim's own solution " << fixed(theirs.*field, 2) << "\n";
    markers[label]["opensim"] = theirs.*field;
  };
  out << "marker RMS (mm), same model and markers:\n";
  marker_row("  pelvis + legs", &MarkerRms::lower_body);
  marker_row("  torso (4 markers)", &MarkerRms::upper_body);
  marker_row("  all 31 tracked", &MarkerRms::all);
  marker_row("  all, IK-weighted", &MarkerRms::weighted);
  // OpenSim's model with its markers re-placed by us on the static trial:
  // what the residual owes to marker placement.
  const motion::MarkerPlacement placed = motion::place_markers(
      s.skeleton, mmm::opensim::read_trc(pipelines() / "subject01_static.trc"), mapping);
  const motion::FusedMotion replaced = motion::fuse_motion(
      placed.skeleton, s.walk, mapping, walk_options(motion::FilterMode::kSmoother));
  const MarkerRms replaced_rms = marker_rms(replaced, replaced.marker_errors);
  double worst_leg = 0.0;
  std::string worst_name;
  for (const motion::CoordinateDifference& d : motion::compare_coordinates(replaced, s.reference)) {
    for (const auto& [c, l] : kLimits) {
      if (c == d.coordinate && d.rms > worst_leg) {
        worst_leg = d.rms;
        worst_name = c;
      }
    }
  }
  out << "OpenSim's model, markers re-placed on subject01_static.trc (smoother): marker RMS "
      << fixed(replaced_rms.lower_body, 2) << " mm pelvis + legs, " << fixed(replaced_rms.all, 2)
      << " mm all; worst leg angle vs OpenSim " << fixed(worst_leg, 2) << " deg (" << worst_name
      << ")\n";
  markers["markers re-placed"] = {{"pelvis + legs", replaced_rms.lower_body},
                                  {"all", replaced_rms.all},
                                  {"worst_leg_angle_rms_deg", worst_leg},
                                  {"worst_leg_angle", worst_name}};
  // The plot: both legs' angles, ours (smoother) over OpenSim's.
  motion::AnglePlotOptions plot;
  plot.title = "subject01_walk1: mmm (smoother) vs OpenSim IK, OpenSim's scaled model";
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  const std::filesystem::path folder = out_dir != nullptr ? out_dir : ".";
  mmm::plot::write_svg(motion::joint_angle_svg(*smoothed, &s.reference, plot),
                       folder / "motion_angles.svg");
  out << "plot: " << (folder / "motion_angles.svg").string() << "\n";
  return {
      {"coordinates", coordinates}, {"marker_rms_mm", markers}, {"frames", smoothed->num_frames()}};
}

// RMS of the second difference of a coordinate over the frames (deg/s^2):
// how rough the curve is.
double roughness(const motion::FusedMotion& fused, const std::string& coordinate) {
  const int c = *fused.coordinate_index(coordinate);
  double squares = 0;
  Eigen::Index count = 0;
  for (Eigen::Index k = 1; k + 1 < fused.num_frames(); ++k) {
    const double dt = fused.times(k + 1) - fused.times(k);
    const double a =
        (fused.coordinates(k + 1, c) - 2 * fused.coordinates(k, c) + fused.coordinates(k - 1, c)) /
        (dt * dt) * 180.0 / 3.14159265358979;
    squares += a * a;
    ++count;
  }
  return std::sqrt(squares / static_cast<double>(std::max<Eigen::Index>(1, count)));
}

nlohmann::json filter_sweep(std::ostream& out) {
  nlohmann::json rows = nlohmann::json::array();
  const Subject& s = subject();
  const motion::MarkerMapping mapping = motion::gait2392_marker_mapping();
  out << "\nfilter sweep (smoother): sigma_a rad/s^2 -> worst RMS vs OpenSim over the leg "
         "angles (deg), knee_angle_r roughness (deg/s^2), marker RMS (mm)\n";
  for (const double sigma : {1000.0, 300.0, 100.0, 50.0, 30.0, 10.0}) {
    motion::MotionFusionOptions options = walk_options(motion::FilterMode::kSmoother);
    options.filter.angular_acceleration_sd = sigma;
    const motion::FusedMotion fused = motion::fuse_motion(s.skeleton, s.walk, mapping, options);
    double worst = 0;
    for (const motion::CoordinateDifference& d : motion::compare_coordinates(fused, s.reference)) {
      for (const auto& [c, l] : kLimits) {
        if (c == d.coordinate) worst = std::max(worst, d.rms);
      }
    }
    out << "  " << std::setw(8) << sigma << " " << std::setw(8) << fixed(worst, 2) << " "
        << std::setw(10) << fixed(roughness(fused, "knee_angle_r"), 0) << " "
        << fixed(fused.overall_rms_mm(), 2) << "\n";
    rows.push_back({{"sigma_a", sigma},
                    {"worst_leg_rms_deg", worst},
                    {"knee_roughness_deg_s2", roughness(fused, "knee_angle_r")}});
  }
  const motion::FusedMotion raw =
      motion::fuse_motion(s.skeleton, s.walk, mapping, walk_options(motion::FilterMode::kNone));
  out << "  none     0.00 " << std::setw(10) << fixed(roughness(raw, "knee_angle_r"), 0) << "\n";
  return rows;
}

// A gap: the right shank and foot clusters vanish for 0.2 s mid-swing.
// Knee and ankle against the full-data answer, per filter.
nlohmann::json gap_table(std::ostream& out) {
  const Subject& s = subject();
  const motion::MarkerMapping mapping = motion::gait2392_marker_mapping();
  mmm::opensim::MarkerTrajectories gappy = s.walk;
  const Eigen::Index first = *gappy.frame_at_time(1.3);
  const Eigen::Index last = *gappy.frame_at_time(1.5);
  for (const char* name : {"R.Shank.Upper", "R.Shank.Front", "R.Shank.Rear", "R.Midfoot.Sup",
                           "R.Midfoot.Lat", "R.Toe.Lat", "R.Toe.Med"}) {
    const Eigen::Index column = 3 * *gappy.marker_index(name);
    gappy.positions.block(first, column, last - first + 1, 3).setConstant(std::nan(""));
  }
  const motion::FusedMotion full =
      motion::fuse_motion(s.skeleton, s.walk, mapping, walk_options(motion::FilterMode::kNone));
  out << "\ngap 1.3-1.5 s (right shank and midfoot/toe markers missing): worst error in the gap "
         "vs the full-data answer (deg)\n";
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& [name, mode] : std::vector<std::pair<std::string, motion::FilterMode>>{
           {"none", motion::FilterMode::kNone}, {"smoother", motion::FilterMode::kSmoother}}) {
    const motion::FusedMotion fused =
        motion::fuse_motion(s.skeleton, gappy, mapping, walk_options(mode));
    out << "  " << std::setw(10) << name;
    nlohmann::json row = {{"filter", name}};
    for (const char* coordinate : {"knee_angle_r", "ankle_angle_r", "hip_rotation_r"}) {
      const int c = *fused.coordinate_index(coordinate);
      double worst = 0;
      for (Eigen::Index k = 0; k < fused.num_frames(); ++k) {
        if (fused.times(k) < 1.3 - 1e-6 || fused.times(k) > 1.5 + 1e-6) continue;
        worst = std::max(worst, std::abs(fused.coordinates(k, c) - full.coordinates(k, c)) * 180.0 /
                                    3.14159265358979);
      }
      out << " " << coordinate << " " << fixed(worst, 2);
      row[coordinate] = worst;
    }
    out << "\n";
    rows.push_back(row);
  }
  return rows;
}

// Our own pipeline for the subject: joint centres and ASIS from the static
// trial (Harrington hips, marker-midpoint knees and ankles), the default
// atlas scaled onto them, markers placed from the static trial.
//
// The station's knee landmark is the patella centre, which no marker
// gives: it is taken where the atlas has it relative to the knee centre,
// turned by the pelvis (atlas -> lab: Kabsch of ASIS r/l and hip centre)
// and the femur's direction, and stretched by the femur's length ratio.
mmm::landmarks::LandmarkSet static_trial_station(const mmm::atlas::Atlas& atlas,
                                                 const mmm::landmarks::LandmarkSet& trial) {
  const auto lab = [&](const char* name) { return trial.find(name)->position_mm; };
  const auto rest = [&](const char* name) { return atlas.find_landmark(name)->position; };
  Eigen::MatrixX3d from(3, 3);
  Eigen::MatrixX3d to(3, 3);
  const std::array<const char*, 3> pelvis = {"asis_r", "asis_l", "femoral_head_centre_r"};
  for (int i = 0; i < 3; ++i) {
    from.row(i) = rest(pelvis.at(static_cast<std::size_t>(i))).transpose();
    to.row(i) = lab(pelvis.at(static_cast<std::size_t>(i))).transpose();
  }
  const Eigen::Matrix3d turn = mmm::fit::rigid_fit(from, to).rigid.linear();
  const Eigen::Vector3d femur_rest = turn * (rest("knee_centre_r") - rest("femoral_head_centre_r"));
  const Eigen::Vector3d femur = lab("knee_centre_r") - lab("femoral_head_centre_r");
  const Eigen::Matrix3d bend = Eigen::Quaterniond::FromTwoVectors(femur_rest, femur).matrix();
  const double stretch = femur.norm() / femur_rest.norm();
  mmm::landmarks::LandmarkSet set;
  set.frame = "lab";
  set.source = "static_trial";
  for (const char* name : {"femoral_head_centre_r", "ankle_centre_r", "asis_r", "asis_l"}) {
    set.landmarks.push_back({name, lab(name), {}, {}});
  }
  const Eigen::Vector3d patella =
      lab("knee_centre_r") +
      stretch * bend * turn * (rest("patella_centre_r") - rest("knee_centre_r"));
  set.landmarks.push_back({"patella_centre_r", patella, {}, {}});
  return set;
}

struct OwnScaling {
  motion::Skeleton scaled;  // markers as the atlas has them
  motion::MarkerPlacement placed;
};

const OwnScaling& own_scaling() {
  static const OwnScaling data = [] {
    const char* dir = std::getenv("MMM_BENCH_ATLAS");
    const std::filesystem::path atlas_dir = dir != nullptr ? dir : "build/atlas/vhf_right_leg";
    mmm::atlas::Atlas atlas = mmm::atlas::read_atlas(atlas_dir);
    mmm::atlas::AtlasMeshes meshes = mmm::atlas::read_atlas_meshes(atlas, atlas_dir);
    const mmm::opensim::MarkerTrajectories standing =
        mmm::opensim::read_trc(pipelines() / "subject01_static.trc");
    const mmm::landmarks::LandmarkSet centres =
        mmm::landmarks::landmarks_from_static_trial(standing).landmarks;
    const mmm::landmarks::LandmarkSet station = static_trial_station(atlas, centres);
    const auto prepared = mmm::scaling::prepare_atlas(atlas, meshes);
    const mmm::scaling::ScaledAtlas scaled = mmm::scaling::scale_atlas(*prepared, station);
    OwnScaling own;
    own.scaled = motion::skeleton_from_atlas(scaled.atlas);
    own.placed = motion::place_markers(own.scaled, standing, motion::gait2392_marker_mapping());
    return own;
  }();
  return data;
}

nlohmann::json own_scaling_table(std::ostream& out) {
  nlohmann::json rows = nlohmann::json::array();
  const Subject& s = subject();
  const OwnScaling& own = own_scaling();
  const motion::MarkerMapping mapping = motion::gait2392_marker_mapping();
  const motion::FusedMotion generic_markers =
      motion::fuse_motion(own.scaled, s.walk, mapping, walk_options(motion::FilterMode::kSmoother));
  const motion::FusedMotion placed = motion::fuse_motion(
      own.placed.skeleton, s.walk, mapping, walk_options(motion::FilterMode::kSmoother));
  std::map<std::string, motion::CoordinateDifference> a;
  std::map<std::string, motion::CoordinateDifference> b;
  for (const auto& d : motion::compare_coordinates(generic_markers, s.reference))
    a[d.coordinate] = d;
  for (const auto& d : motion::compare_coordinates(placed, s.reference)) b[d.coordinate] = d;
  out << "\nours with our own scaling (static-trial landmarks -> default atlas scaled) vs "
         "OpenSim IK; RMS (mean offset) in deg / mm\n"
      << "  static pose marker RMS " << fixed(own.placed.rms_before_mm, 1) << " mm before placing, "
      << fixed(own.placed.rms_after_mm, 1) << " mm after\n";
  out << std::left << std::setw(20) << "coordinate"
      << " " << std::setw(22) << "atlas markers"
      << " " << std::setw(22) << "markers placed"
      << " placed, offset removed\n";
  for (const auto& [coordinate, d] : b) {
    const double centred = std::sqrt(std::max(0.0, d.rms * d.rms - d.mean * d.mean));
    out << std::setw(20) << coordinate << " " << std::setw(22)
        << fixed(a[coordinate].rms, 2) + " (" + fixed(a[coordinate].mean, 2) + ")"
        << " " << std::setw(22) << fixed(d.rms, 2) + " (" + fixed(d.mean, 2) + ")"
        << " " << fixed(centred, 2) << "\n";
    rows.push_back({{"coordinate", coordinate},
                    {"rms_atlas_markers", a[coordinate].rms},
                    {"mean_atlas_markers", a[coordinate].mean},
                    {"rms_placed", d.rms},
                    {"mean_placed", d.mean},
                    {"rms_placed_without_offset", centred}});
  }
  out << std::setw(20) << "marker RMS (mm)"
      << " " << std::setw(22) << fixed(generic_markers.overall_rms_mm(), 2) << " " << std::setw(22)
      << fixed(placed.overall_rms_mm(), 2) << "\n";
  motion::AnglePlotOptions plot;
  plot.title = "subject01_walk1: mmm on the default atlas scaled to subject01 vs OpenSim IK";
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  mmm::plot::write_svg(
      motion::joint_angle_svg(placed, &s.reference, plot),
      std::filesystem::path(out_dir != nullptr ? out_dir : ".") / "motion_angles_own_scaling.svg");
  return {
      {"coordinates", rows},
      {"marker_rms_mm",
       {{"atlas_markers", generic_markers.overall_rms_mm()}, {"placed", placed.overall_rms_mm()}}},
      {"static_pose_rms_mm",
       {{"before", own.placed.rms_before_mm}, {"after", own.placed.rms_after_mm}}}};
}

// The tables on stdout and beside the JSON (motion.accuracy.txt), which
// bench/table.py prints above the speed table.
void write_accuracy_table() {
  std::ostringstream text;
  nlohmann::json document;
  document["opensim_model"] = accuracy_table(text);
  document["filter_sweep"] = filter_sweep(text);
  document["gap"] = gap_table(text);
  document["own_scaling"] = own_scaling_table(text);
  std::cout << text.str();
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  const std::filesystem::path folder = out_dir != nullptr ? out_dir : ".";
  std::ofstream(folder / "motion.accuracy.json") << document.dump(2) << "\n";
  std::ofstream(folder / "motion.accuracy.txt") << text.str();
}

// The kinematic fit alone: one Ceres solve per frame, warm-started from the
// previous frame, over the 121 frames (items = frames).
void BM_ChainFitPerFrame(benchmark::State& state) {
  const Subject& s = subject();
  const motion::FusedMotion fused =
      motion::fuse_motion(s.skeleton, s.walk, motion::gait2392_marker_mapping(),
                          walk_options(motion::FilterMode::kNone));
  std::vector<Eigen::MatrixX3d> targets;
  for (Eigen::Index k = 0; k < fused.num_frames(); ++k) targets.push_back(targets_of(fused, k));
  motion::ChainFitter fitter(s.skeleton, fused.setup);
  for (auto _ : state) {
    Eigen::VectorXd q = fused.coordinates.row(0).transpose();
    for (const Eigen::MatrixX3d& frame : targets) q = fitter.fit(frame, q).q;
    benchmark::DoNotOptimize(q.data());
  }
  state.SetItemsProcessed(state.iterations() * fused.num_frames());
}
BENCHMARK(BM_ChainFitPerFrame)->Unit(benchmark::kMillisecond);

// The whole fusion of the trial (free-body registrations, start, fit,
// Kalman filter, smoother, poses, errors), items = frames.
void BM_FuseTrialSmoother(benchmark::State& state) {
  const Subject& s = subject();
  const motion::MarkerMapping mapping = motion::gait2392_marker_mapping();
  Eigen::Index frames = 0;
  for (auto _ : state) {
    const motion::FusedMotion fused = motion::fuse_motion(
        s.skeleton, s.walk, mapping, walk_options(motion::FilterMode::kSmoother));
    frames = fused.num_frames();
    benchmark::DoNotOptimize(fused.coordinates.data());
  }
  state.SetItemsProcessed(state.iterations() * frames);
}
BENCHMARK(BM_FuseTrialSmoother)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return mmm::bench::run_suite(argc, argv, "mmm_bench_motion", write_accuracy_table);
}

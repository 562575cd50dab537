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

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/atlas/atlas_meshes.h"
#include "core/fit/rigid_fit.h"
#include "core/landmarks/static_trial_landmarks.h"
#include "core/motion/chain_fit.h"
#include "core/motion/marker_placement.h"
#include "core/motion/marker_mapping.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/motion_tables.h"
#include "core/motion/skeleton.h"
#include "core/opensim/mot.h"
#include "core/opensim/osim_model.h"
#include "core/opensim/trc.h"
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

void accuracy_table(std::ostream& out) {
  const Subject& s = subject();
  const motion::MarkerMapping mapping = motion::gait2392_marker_mapping();
  const std::vector<std::pair<std::string, motion::FilterMode>> modes = {
      {"none", motion::FilterMode::kNone},
      {"forward", motion::FilterMode::kForward},
      {"smoother", motion::FilterMode::kSmoother}};
  std::map<std::string, std::map<std::string, motion::CoordinateDifference>> by_mode;
  std::map<std::string, double> marker_rms;
  for (const auto& [name, mode] : modes) {
    const motion::FusedMotion fused =
        motion::fuse_motion(s.skeleton, s.walk, mapping, walk_options(mode));
    for (const motion::CoordinateDifference& d : motion::compare_coordinates(fused, s.reference)) {
      by_mode[name][d.coordinate] = d;
    }
    marker_rms[name] = fused.overall_rms_mm();
    if (mode == motion::FilterMode::kNone) {
      out << "per-marker RMS (mm):";
      for (Eigen::Index m = 0; m < fused.marker_errors.cols(); ++m) {
        double squares = 0;
        int count = 0;
        for (Eigen::Index f = 0; f < fused.marker_errors.rows(); ++f) {
          if (std::isfinite(fused.marker_errors(f, m))) {
            squares += fused.marker_errors(f, m) * fused.marker_errors(f, m);
            ++count;
          }
        }
        out << " " << fused.marker_names[static_cast<std::size_t>(m)] << " "
            << fixed(std::sqrt(squares / std::max(1, count)), 1);
      }
      out << "\n";
    }
    for (const std::string& note : fused.notes) out << "note (" << name << "): " << note << "\n";
  }
  out << "\nours vs OpenSim IK, subject01_walk1 0.5-2.5 s, OpenSim's scaled model; RMS "
         "difference (deg, pelvis translations mm) per filter\n";
  out << std::left << std::setw(20) << "coordinate";
  for (const auto& [name, mode] : modes) out << " " << std::setw(10) << name;
  out << " limit\n";
  for (const auto& [coordinate, difference] : by_mode["none"]) {
    out << std::setw(20) << coordinate;
    for (const auto& [name, mode] : modes) {
      out << " " << std::setw(10) << fixed(by_mode[name][coordinate].rms, 2);
    }
    std::string limit;
    for (const auto& [c, l] : kLimits) {
      if (c == coordinate) limit = "<= " + fixed(l, 0);
    }
    out << " " << limit << "\n";
  }
  out << std::setw(20) << "marker RMS (mm)";
  for (const auto& [name, mode] : modes) out << " " << std::setw(10) << fixed(marker_rms[name], 2);
  out << " <= 10\n";
}

// RMS of the second difference of a coordinate over the frames (deg/s^2):
// how rough the curve is.
double roughness(const motion::FusedMotion& fused, const std::string& coordinate) {
  const int c = *fused.coordinate_index(coordinate);
  double squares = 0;
  Eigen::Index count = 0;
  for (Eigen::Index k = 1; k + 1 < fused.num_frames(); ++k) {
    const double dt = fused.times(k + 1) - fused.times(k);
    const double a = (fused.coordinates(k + 1, c) - 2 * fused.coordinates(k, c) +
                      fused.coordinates(k - 1, c)) /
                     (dt * dt) * 180.0 / 3.14159265358979;
    squares += a * a;
    ++count;
  }
  return std::sqrt(squares / static_cast<double>(std::max<Eigen::Index>(1, count)));
}

void filter_sweep(std::ostream& out) {
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
  }
  const motion::FusedMotion raw = motion::fuse_motion(s.skeleton, s.walk, mapping,
                                                      walk_options(motion::FilterMode::kNone));
  out << "  none     0.00 " << std::setw(10) << fixed(roughness(raw, "knee_angle_r"), 0) << "\n";
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
  const char* pelvis[] = {"asis_r", "asis_l", "femoral_head_centre_r"};
  for (int i = 0; i < 3; ++i) {
    from.row(i) = rest(pelvis[i]).transpose();
    to.row(i) = lab(pelvis[i]).transpose();
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

void own_scaling_table(std::ostream& out) {
  const Subject& s = subject();
  const OwnScaling& own = own_scaling();
  const motion::MarkerMapping mapping = motion::gait2392_marker_mapping();
  const motion::FusedMotion generic_markers = motion::fuse_motion(
      own.scaled, s.walk, mapping, walk_options(motion::FilterMode::kSmoother));
  const motion::FusedMotion placed = motion::fuse_motion(
      own.placed.skeleton, s.walk, mapping, walk_options(motion::FilterMode::kSmoother));
  std::map<std::string, motion::CoordinateDifference> a;
  std::map<std::string, motion::CoordinateDifference> b;
  for (const auto& d : motion::compare_coordinates(generic_markers, s.reference)) a[d.coordinate] = d;
  for (const auto& d : motion::compare_coordinates(placed, s.reference)) b[d.coordinate] = d;
  out << "\nours with our own scaling (static-trial landmarks -> default atlas scaled) vs "
         "OpenSim IK; RMS (mean offset) in deg / mm\n"
      << "  static pose marker RMS " << fixed(own.placed.rms_before_mm, 1) << " mm before placing, "
      << fixed(own.placed.rms_after_mm, 1) << " mm after\n";
  out << std::left << std::setw(20) << "coordinate" << " " << std::setw(22) << "atlas markers"
      << " " << std::setw(22) << "markers placed" << "\n";
  for (const auto& [coordinate, d] : b) {
    out << std::setw(20) << coordinate << " " << std::setw(22)
        << fixed(a[coordinate].rms, 2) + " (" + fixed(a[coordinate].mean, 2) + ")" << " "
        << std::setw(22) << fixed(d.rms, 2) + " (" + fixed(d.mean, 2) + ")" << "\n";
  }
  out << std::setw(20) << "marker RMS (mm)" << " " << std::setw(22)
      << fixed(generic_markers.overall_rms_mm(), 2) << " " << std::setw(22)
      << fixed(placed.overall_rms_mm(), 2) << "\n";
}

void write_accuracy_table() {
  std::ostringstream text;
  accuracy_table(text);
  filter_sweep(text);
  own_scaling_table(text);
  std::cout << text.str();
}

void BM_ChainFitPerFrame(benchmark::State& state) {
  const Subject& s = subject();
  const motion::FusedMotion fused = motion::fuse_motion(
      s.skeleton, s.walk, motion::gait2392_marker_mapping(),
      walk_options(motion::FilterMode::kNone));
  for (auto _ : state) {
    const motion::FusedMotion again = motion::fuse_motion(
        s.skeleton, s.walk, motion::gait2392_marker_mapping(),
        walk_options(motion::FilterMode::kNone));
    benchmark::DoNotOptimize(again.coordinates.data());
  }
  state.SetItemsProcessed(state.iterations() * fused.num_frames());
}
BENCHMARK(BM_ChainFitPerFrame)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  try {
    benchmark::Initialize(&argc, argv);
    if (std::getenv("MMM_BENCH_SKIP_ACCURACY") == nullptr) write_accuracy_table();
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
  } catch (const std::exception& error) {
    std::cerr << "mmm_bench_motion: " << error.what() << "\n";
    return 1;
  }
  return 0;
}

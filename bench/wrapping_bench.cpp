// Muscle wrapping (issue 8, in progress): what exists so far. The action
// lines' hip-flexion moment arms on the default atlas (gait2392's paths
// carried onto the Visible Human Female's bones) beside the gait2392
// model's own, over hip flexion -20..60 degrees; and the speed of a path
// and moment-arm evaluation.
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
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/motion/skeleton.h"
#include "core/opensim/osim_model.h"
#include "core/wrapping/action_line_path.h"
#include "core/wrapping/osim_action_lines.h"

namespace {

namespace motion = mmm::motion;
namespace wrapping = mmm::wrapping;
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

// Hip-flexion moment arm (mm) of one line at each angle (deg), everything
// else at its default.
std::vector<double> hip_flexion_arms(const mmm::atlas::Atlas& atlas,
                                     const motion::Skeleton& skeleton,
                                     const mmm::atlas::Muscle& muscle,
                                     const mmm::atlas::ActionLine& line,
                                     const std::vector<double>& angles) {
  const int hip = *skeleton.coordinate_index("hip_flexion_r");
  std::vector<double> arms;
  for (const double angle : angles) {
    Eigen::VectorXd q = skeleton.default_coordinates();
    q(hip) = angle * kDeg;
    arms.push_back(wrapping::moment_arm(atlas, muscle, line, skeleton, q, hip));
  }
  return arms;
}

void write_accuracy_table() {
  const Models& m = models();
  std::vector<double> angles;
  for (int a = -20; a <= 60; a += 10) angles.push_back(a);
  std::ostringstream out;
  out << "\nhip-flexion moment arms (mm, + flexor): default atlas (VHF bones) vs the gait2392 "
         "model, hip flexion -20..60 deg, other joints at 0\n"
      << std::left << std::setw(16) << "action line" << std::setw(20) << "atlas at -20/20/60"
      << std::setw(20) << "gait2392 -20/20/60"
      << "RMS difference\n";
  nlohmann::json rows = nlohmann::json::array();
  for (const mmm::atlas::Muscle& muscle : m.atlas.muscles) {
    for (const mmm::atlas::ActionLine& line : muscle.action_lines) {
      const mmm::atlas::Muscle* theirs = m.gait2392.find_muscle(line.name);
      if (theirs == nullptr) continue;
      const std::vector<double> ours =
          hip_flexion_arms(m.atlas, m.atlas_skeleton, muscle, line, angles);
      const std::vector<double> reference = hip_flexion_arms(
          m.gait2392, m.gait2392_skeleton, *theirs, theirs->action_lines.front(), angles);
      double squares = 0;
      for (std::size_t i = 0; i < angles.size(); ++i) {
        squares += (ours[i] - reference[i]) * (ours[i] - reference[i]);
      }
      const double rms = std::sqrt(squares / static_cast<double>(angles.size()));
      if (std::abs(reference[4]) < 5.0 && std::abs(ours[4]) < 5.0) continue;  // not a hip muscle
      const auto triple = [](const std::vector<double>& v) {
        std::ostringstream t;
        t << std::fixed << std::setprecision(0) << v[0] << "/" << v[4] << "/" << v[8];
        return t.str();
      };
      out << std::setw(16) << line.name << std::setw(20) << triple(ours) << std::setw(20)
          << triple(reference) << std::fixed << std::setprecision(1) << rms << "\n";
      rows.push_back({{"action_line", line.name},
                      {"muscle", muscle.name},
                      {"angles_deg", angles},
                      {"atlas_mm", ours},
                      {"gait2392_mm", reference},
                      {"rms_mm", rms}});
    }
  }
  std::cout << out.str();
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  const std::filesystem::path folder = out_dir != nullptr ? out_dir : ".";
  std::ofstream(folder / "wrapping.accuracy.txt") << out.str();
  std::ofstream(folder / "wrapping.accuracy.json")
      << nlohmann::json{{"hip_flexion_moment_arms", rows}}.dump(2) << "\n";
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

}  // namespace

int main(int argc, char** argv) {
  try {
    benchmark::Initialize(&argc, argv);
    if (std::getenv("MMM_BENCH_SKIP_ACCURACY") == nullptr) write_accuracy_table();
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
  } catch (const std::exception& error) {
    std::cerr << "mmm_bench_wrapping: " << error.what() << "\n";
    return 1;
  }
  return 0;
}

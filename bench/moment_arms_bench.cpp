// Moment arms of the default atlas's action lines against gait2392's own
// paths (evaluated by mmm the same way, on the model's bodies): every line
// and every coordinate it crosses, one coordinate swept at a time (hip
// flexion -20..90, adduction -30..30, rotation -40..40, knee 0..120, ankle
// -30..30 deg; the others at 0), every degree. Prints the table and the
// targets (median RMS difference <= 5 mm, none beyond 15 mm, signs agreeing
// where gait2392's moment arm exceeds 10 mm, no change faster than 2 mm per
// degree in moment arm or length), writes moment_arms.accuracy.{txt,json},
// one CSV row per line, coordinate and angle, and one SVG of small multiples
// per coordinate. The benchmark times one full sweep of every line.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_main.h"
#include "core/atlas/atlas_io.h"
#include "core/motion/skeleton.h"
#include "core/opensim/osim_model.h"
#include "core/plot/svg_plot.h"
#include "core/wrapping/moment_arm_sweep.h"
#include "core/wrapping/osim_action_lines.h"
#include "core/wrapping/wrapping_summary.h"

namespace {

namespace wrapping = mmm::wrapping;

struct SweepModels {
  mmm::atlas::Atlas atlas;
  mmm::motion::Skeleton atlas_skeleton;
  mmm::atlas::Atlas gait2392;
  mmm::motion::Skeleton gait2392_skeleton;
};

const SweepModels& sweep_models() {
  static const SweepModels data = [] {
    SweepModels m;
    const char* dir = std::getenv("MMM_BENCH_ATLAS");
    m.atlas = mmm::atlas::read_atlas(dir != nullptr ? dir : "build/atlas/vhf_right_leg");
    m.atlas_skeleton = mmm::motion::skeleton_from_atlas(m.atlas);
    const mmm::opensim::OsimModel model = mmm::opensim::read_osim(
        std::filesystem::path(MMM_DATA_DIR) / "gait2392" / "gait2392_thelen2003muscle.osim");
    m.gait2392 = wrapping::osim_action_lines(model);
    m.gait2392_skeleton = mmm::motion::skeleton_from_osim(model);
    return m;
  }();
  return data;
}

// A line crosses a coordinate when either model gives it a moment arm.
constexpr double kCrossesMm = 2.0;

double largest_magnitude(const std::vector<double>& values) {
  double largest = 0.0;
  for (const double v : values) largest = std::max(largest, std::abs(v));
  return largest;
}

std::string range_text(const std::vector<double>& values) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(0) << *std::ranges::min_element(values) << ".."
       << *std::ranges::max_element(values);
  return text.str();
}

wrapping::PathOptions path_options() {
  wrapping::PathOptions options;
  if (const char* blend = std::getenv("MMM_BENCH_CONDITIONAL_BLEND_DEG")) {
    options.conditional_blend = std::stod(blend) * std::numbers::pi / 180.0;
  }
  return options;
}

void write_accuracy_table() {
  const SweepModels& m = sweep_models();
  const wrapping::PathOptions options = path_options();
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  const std::filesystem::path folder = out_dir != nullptr ? out_dir : ".";
  std::ostringstream out;
  std::ostringstream csv;
  csv << "muscle,action_line,coordinate,angle_deg,atlas_moment_arm_mm,gait2392_moment_arm_mm,"
         "atlas_length_mm,gait2392_length_mm\n";
  out << "moment arms (mm, OpenSim sign -dL/dq): default atlas vs gait2392's own paths, one "
         "coordinate swept, others at 0\n"
      << std::left << std::setw(30) << "muscle / action line" << std::setw(17) << "coordinate"
      << std::setw(14) << "gait2392" << std::setw(14) << "atlas" << std::right << std::setw(8)
      << "RMS" << std::setw(8) << "max" << std::setw(10) << "sign off" << std::setw(14)
      << "jump mm/deg" << '\n';
  nlohmann::json rows = nlohmann::json::array();
  std::vector<double> rms_all;
  int beyond_15 = 0;
  int sign_off = 0;
  int jumps = 0;
  std::map<std::string, std::vector<mmm::plot::Chart>> charts;
  std::vector<std::string> without_reference;
  for (const mmm::atlas::Muscle& muscle : m.atlas.muscles) {
    for (const mmm::atlas::ActionLine& line : muscle.action_lines) {
      const mmm::atlas::Muscle* theirs = m.gait2392.find_muscle(line.name);
      for (const wrapping::CoordinateSweep& sweep : wrapping::right_leg_sweeps()) {
        const wrapping::LineSweep ours =
            wrapping::sweep_line(m.atlas, muscle, line, m.atlas_skeleton, sweep, 1.0, options);
        if (theirs == nullptr) {
          if (largest_magnitude(ours.moment_arm_mm) < kCrossesMm) continue;
          const double jump =
              std::max(wrapping::largest_jump_per_deg(ours.angles_deg, ours.moment_arm_mm),
                       wrapping::largest_jump_per_deg(ours.angles_deg, ours.length_mm));
          std::ostringstream note;
          note << line.name << " " << sweep.coordinate << " " << range_text(ours.moment_arm_mm)
               << " mm, largest change " << std::fixed << std::setprecision(2) << jump << " mm/deg";
          without_reference.push_back(note.str());
          if (jump > 2.0) ++jumps;
          continue;
        }
        const wrapping::LineSweep reference =
            wrapping::sweep_line(m.gait2392, *theirs, theirs->action_lines.front(),
                                 m.gait2392_skeleton, sweep, 1.0, options);
        if (largest_magnitude(reference.moment_arm_mm) < kCrossesMm &&
            largest_magnitude(ours.moment_arm_mm) < kCrossesMm) {
          continue;
        }
        const wrapping::SweepComparison c = wrapping::compare_sweeps(ours, reference);
        const double jump = std::max(c.max_arm_jump_mm_per_deg, c.max_length_jump_mm_per_deg);
        rms_all.push_back(c.rms_mm);
        if (c.rms_mm > 15.0) ++beyond_15;
        if (c.sign_disagrees > 0) ++sign_off;
        if (jump > 2.0) ++jumps;
        out << std::left << std::setw(30) << (muscle.name.substr(0, 14) + " / " + line.name)
            << std::setw(17) << sweep.coordinate << std::setw(14)
            << range_text(reference.moment_arm_mm) << std::setw(14)
            << range_text(ours.moment_arm_mm) << std::right << std::fixed << std::setprecision(1)
            << std::setw(8) << c.rms_mm << std::setw(8) << c.max_abs_mm << std::setw(10)
            << (std::to_string(c.sign_disagrees) + "/" + std::to_string(c.sign_checked))
            << std::setw(14) << std::setprecision(2) << jump << '\n';
        rows.push_back({{"muscle", muscle.name},
                        {"action_line", line.name},
                        {"coordinate", sweep.coordinate},
                        {"rms_mm", c.rms_mm},
                        {"max_difference_mm", c.max_abs_mm},
                        {"sign_checked", c.sign_checked},
                        {"sign_disagrees", c.sign_disagrees},
                        {"max_moment_arm_change_mm_per_deg", c.max_arm_jump_mm_per_deg},
                        {"max_length_change_mm_per_deg", c.max_length_jump_mm_per_deg}});
        for (std::size_t i = 0; i < ours.angles_deg.size(); ++i) {
          csv << muscle.name << ',' << line.name << ',' << sweep.coordinate << ','
              << ours.angles_deg[i] << ',' << ours.moment_arm_mm[i] << ','
              << reference.moment_arm_mm[i] << ',' << ours.length_mm[i] << ','
              << reference.length_mm[i] << '\n';
        }
        mmm::plot::Chart chart;
        chart.title = line.name;
        chart.x_label = sweep.coordinate + " (deg)";
        chart.y_label = "moment arm (mm)";
        chart.series = {{"atlas", ours.angles_deg, ours.moment_arm_mm, "", false, 1.5},
                        {"gait2392", reference.angles_deg, reference.moment_arm_mm, "", true, 1.5}};
        chart.y_reference_lines = {0.0};
        charts[sweep.coordinate].push_back(std::move(chart));
      }
    }
  }
  const double median = rms_all.empty() ? 0.0 : wrapping::median(rms_all);
  out << std::fixed << std::setprecision(1) << "\n"
      << rms_all.size() << " line-coordinate pairs against gait2392: median RMS difference "
      << median << " mm (target <= 5), " << beyond_15 << " beyond 15 mm (target 0), " << sign_off
      << " with a sign against gait2392's where it exceeds 10 mm (target 0), " << jumps
      << " changing faster than 2 mm/deg (target 0)\n";
  if (!without_reference.empty()) {
    out << "lines without a gait2392 path (no reference):\n";
    for (const std::string& note : without_reference) out << "  " << note << '\n';
  }
  std::cout << out.str();
  std::ofstream(folder / "moment_arms.accuracy.txt") << out.str();
  std::ofstream(folder / "moment_arms.accuracy.json")
      << nlohmann::json{{"pairs", rows},
                        {"median_rms_mm", median},
                        {"beyond_15_mm", beyond_15},
                        {"sign_disagreements", sign_off},
                        {"faster_than_2_mm_per_deg", jumps}}
             .dump(2)
      << '\n';
  std::ofstream(folder / "moment_arms.csv") << csv.str();
  for (const auto& [coordinate, panels] : charts) {
    mmm::plot::Layout layout;
    layout.columns = 6;
    layout.panel_width = 260;
    layout.panel_height = 180;
    layout.title = "Moment arms over " + coordinate + ": atlas (solid) and gait2392 (dashed)";
    mmm::plot::write_svg(mmm::plot::svg_small_multiples(panels, layout),
                         folder / ("moment_arms_" + coordinate + ".svg"));
  }
}

// One hip-flexion sweep (every 5 deg) of every atlas action line (items = lines).
void BM_HipFlexionSweepOfEveryLine(benchmark::State& state) {
  const SweepModels& m = sweep_models();
  std::int64_t lines = 0;
  for (auto _ : state) {
    for (const mmm::atlas::Muscle& muscle : m.atlas.muscles) {
      for (const mmm::atlas::ActionLine& line : muscle.action_lines) {
        benchmark::DoNotOptimize(wrapping::sweep_line(m.atlas, muscle, line, m.atlas_skeleton,
                                                      {"hip_flexion_r", -20, 90}, 5.0));
        ++lines;
      }
    }
  }
  state.SetItemsProcessed(lines);
}
BENCHMARK(BM_HipFlexionSweepOfEveryLine)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return mmm::bench::run_suite(argc, argv, "mmm_bench_moment_arms", write_accuracy_table);
}

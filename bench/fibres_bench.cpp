// Muscle decomposition into fibres on the default atlas (Visible Human Female
// surfaces at the wrapping resolution, 10K faces). (1) Quality of every
// method on every muscle (81 fibres x 20 segments): fibre points inside the
// muscle, distance of the fibre ends from the muscle's end patches (where it
// lies on its bones, or its end cap where the segmentation stops at a tendon;
// end_patches.h) and coverage of the patches, the tendon gap from each patch
// to its bone area beside the median end distance from the bone area itself,
// spacing and length spread, t-polynomial fit error, points that had to be
// moved inside. (2) Time per decomposition (median of 11) for the
// gluteus medius and the iliacus beside the reference implementation's
// (VPHOP D10.2, section 3.4.3), and 256 fibres x 50 segments by slicing.
// (3) Google Benchmark: the same decompositions.
//
// The tables go to stdout and $MMM_BENCH_OUT_DIR/fibres.accuracy.{txt,json}
// (bench/table.py folds them into build/bench/fibres.json).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_main.h"
#include "core/atlas/atlas_io.h"
#include "core/fibres/fibre_quality.h"
#include "core/fibres/muscle_fibres.h"
#include "core/mesh/aabb_tree.h"
#include "core/wrapping/muscle_hulls.h"

namespace {

namespace fibres = mmm::fibres;
using fibres::DecompositionMethod;

constexpr Eigen::Index kWrappingFaces = 10000;
constexpr std::array kMethods = {DecompositionMethod::kSlicing, DecompositionMethod::kHarmonic,
                                 DecompositionMethod::kMassSpring, DecompositionMethod::kCadaver};

std::filesystem::path atlas_dir() {
  const char* dir = std::getenv("MMM_BENCH_ATLAS");
  return dir != nullptr ? dir : "build/atlas/vhf_right_leg";
}

struct Atlas {
  mmm::atlas::Atlas atlas;
  std::map<std::string, mmm::mesh::IndexedMesh> bones;  // full level
};

const Atlas& atlas() {
  static const Atlas loaded = [] {
    Atlas a{mmm::atlas::read_atlas(atlas_dir()), {}};
    for (const mmm::atlas::Bone& bone : a.atlas.bones) {
      if (!bone.meshes.empty())
        a.bones[bone.name] = mmm::atlas::load_mesh(atlas_dir(), bone.meshes);
    }
    return a;
  }();
  return loaded;
}

std::unique_ptr<fibres::MuscleFibreModel> model(const std::string& muscle,
                                                DecompositionMethod method, int count,
                                                int segments) {
  const mmm::atlas::Muscle& m = *atlas().atlas.find_muscle(muscle);
  fibres::DecompositionOptions options;
  options.fibres = count;
  options.segments = segments;
  options.architecture = m.architecture;
  return std::make_unique<fibres::MuscleFibreModel>(
      m.name, mmm::wrapping::wrapping_surface(m, atlas_dir(), kWrappingFaces),
      fibres::attachment_samples(m,
                                 [](const std::string& bone) -> const mmm::mesh::IndexedMesh& {
                                   return atlas().bones.at(bone);
                                 }),
      method, options);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string fixed(double value, int decimals) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << value;
  return s.str();
}

nlohmann::json quality_table(std::ostringstream& out) {
  out << "== Quality: 81 fibres x 20 segments, every muscle and method (wrapping resolution) ==\n"
      << "inside: fibre points inside the muscle or within 0.5 mm of it; ends: median distance "
         "of the origin / insertion ends from the muscle's end patch (mm); cover: share of patch "
         "vertices within 5 mm of a fibre end; tendon: closest approach of the bone area to its "
         "patch (mm, the unsegmented tendon); to bone: median distance of the ends from the bone "
         "area (mm); moved: points moved inside\n";
  out << std::left << std::setw(30) << "muscle" << std::setw(12) << "method" << std::right
      << std::setw(8) << "inside%" << std::setw(12) << "ends o/i" << std::setw(13) << "cover o/i"
      << std::setw(14) << "tendon o/i" << std::setw(14) << "to bone o/i" << std::setw(9)
      << "spac.cv" << std::setw(9) << "len mm" << std::setw(8) << "len.cv" << std::setw(8)
      << "fit mm" << std::setw(7) << "moved" << std::setw(8) << "ms"
      << "\n";
  nlohmann::json rows = nlohmann::json::array();
  std::map<DecompositionMethod, std::vector<double>> inside;
  std::map<DecompositionMethod, std::vector<double>> ends;
  std::map<DecompositionMethod, std::vector<double>> cover;
  for (const mmm::atlas::Muscle& muscle : atlas().atlas.muscles) {
    for (const DecompositionMethod method : kMethods) {
      const auto m = model(muscle.name, method, 81, 20);
      const fibres::MuscleFibres result = m->decompose_at_rest();
      const fibres::FibreQuality q = fibres::measure_fibre_quality(
          m->rest(), result.fibres, result.attachments.origin, result.attachments.insertion);
      const double gap_o = result.origin_gap_mm;
      const double gap_i = result.insertion_gap_mm;
      const fibres::FibreQuality to_bone = fibres::measure_fibre_quality(
          m->rest(), result.fibres, result.bone_areas.origin, result.bone_areas.insertion);
      const double bone_o = to_bone.origin_end_distance_median_mm;
      const double bone_i = to_bone.insertion_end_distance_median_mm;
      inside[method].push_back(q.inside_fraction);
      ends[method].push_back(q.origin_end_distance_median_mm);
      ends[method].push_back(q.insertion_end_distance_median_mm);
      cover[method].push_back(q.origin_coverage);
      cover[method].push_back(q.insertion_coverage);
      const std::string name(fibres::method_name(method));
      out << std::left << std::setw(30) << muscle.name << std::setw(12) << name << std::right
          << std::setw(8) << fixed(100.0 * q.inside_fraction, 2) << std::setw(12)
          << (fixed(q.origin_end_distance_median_mm, 1) + " / " +
              fixed(q.insertion_end_distance_median_mm, 1))
          << std::setw(13) << (fixed(q.origin_coverage, 2) + " / " + fixed(q.insertion_coverage, 2))
          << std::setw(14) << (fixed(gap_o, 1) + " / " + fixed(gap_i, 1)) << std::setw(14)
          << (fixed(bone_o, 1) + " / " + fixed(bone_i, 1)) << std::setw(9) << fixed(q.spacing_cv, 2)
          << std::setw(9) << fixed(q.length_median_mm, 0) << std::setw(8) << fixed(q.length_cv, 2)
          << std::setw(8) << fixed(q.fit_error_mean_mm, 2) << std::setw(7) << result.moved_inside
          << std::setw(8) << fixed(1000.0 * result.seconds, 1)
          << (result.stand_in_measured ? "  (stand-in measured fibres)" : "") << "\n";
      nlohmann::json row = q;
      row["muscle"] = muscle.name;
      row["method"] = name;
      row["origin_gap_mm"] = gap_o;
      row["insertion_gap_mm"] = gap_i;
      row["origin_to_bone_median_mm"] = bone_o;
      row["insertion_to_bone_median_mm"] = bone_i;
      row["moved_inside"] = result.moved_inside;
      row["stand_in_measured"] = result.stand_in_measured;
      row["ms"] = 1000.0 * result.seconds;
      row["field_ms"] = 1000.0 * m->field_seconds();
      rows.push_back(row);
    }
  }
  out << "over all muscles, per method: lowest inside %; end distance median (mm): median and "
         "largest over the muscles' ends; coverage: median and lowest\n";
  for (const DecompositionMethod method : kMethods) {
    const auto& e = ends[method];
    const auto& c = cover[method];
    out << "  " << std::left << std::setw(12) << fibres::method_name(method) << std::right
        << fixed(100.0 * *std::min_element(inside[method].begin(), inside[method].end()), 2)
        << " %   ends " << fixed(median(e), 2) << " / "
        << fixed(*std::max_element(e.begin(), e.end()), 2) << " mm   cover " << fixed(median(c), 2)
        << " / " << fixed(*std::min_element(c.begin(), c.end()), 2) << "\n";
  }
  return rows;
}

// Median of 11 timed decompositions (s); the model's set-up not included.
double timed(const fibres::MuscleFibreModel& m) {
  std::vector<double> seconds;
  for (int i = 0; i < 11; ++i) {
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(m.decompose_at_rest());
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return median(seconds);
}

nlohmann::json speed_table(std::ostringstream& out) {
  struct Reference {
    const char* muscle;
    double slicing_ms;
    double harmonic_ms;
    double mass_spring_ms;
  };
  const std::array references = {Reference{"gluteus_medius_r", 470, 3230, 10238},
                                 Reference{"iliacus_r", 582, 3064, 13188}};
  out << "\n== Speed: median ms per decomposition (81 fibres x 20 segments; 1 thread) ==\n"
      << std::left << std::setw(20) << "muscle" << std::setw(26) << "method" << std::right
      << std::setw(10) << "ours" << std::setw(12) << "reference" << std::setw(10) << "target"
      << std::setw(9) << "ratio"
      << "\n";
  nlohmann::json rows = nlohmann::json::array();
  const auto row = [&](const std::string& muscle, const std::string& what, double ours_ms,
                       double reference_ms, double target_ms) {
    out << std::left << std::setw(20) << muscle << std::setw(26) << what << std::right
        << std::setw(10) << fixed(ours_ms, 1) << std::setw(12)
        << (reference_ms > 0 ? fixed(reference_ms, 0) : std::string("-")) << std::setw(10)
        << fixed(target_ms, 0) << std::setw(9)
        << (reference_ms > 0 ? fixed(reference_ms / ours_ms, 0) + "x" : std::string("-"))
        << (ours_ms <= target_ms ? "" : "  (over target)") << "\n";
    rows.push_back({{"muscle", muscle},
                    {"method", what},
                    {"ms", ours_ms},
                    {"reference_ms", reference_ms},
                    {"target_ms", target_ms}});
  };
  for (const Reference& r : references) {
    const auto slicing = model(r.muscle, DecompositionMethod::kSlicing, 81, 20);
    row(r.muscle, "slicing", 1000 * timed(*slicing), r.slicing_ms, 50);
    const auto harmonic = model(r.muscle, DecompositionMethod::kHarmonic, 81, 20);
    const double h = 1000 * timed(*harmonic);
    row(r.muscle, "harmonic (field stored)", h, 0, 50);
    row(r.muscle, "harmonic (with field)", h + 1000 * harmonic->field_seconds(), r.harmonic_ms,
        300);
    const auto spring = model(r.muscle, DecompositionMethod::kMassSpring, 81, 20);
    row(r.muscle, "mass-spring", 1000 * timed(*spring), r.mass_spring_ms, 1000);
    const auto cadaver = model(r.muscle, DecompositionMethod::kCadaver, 81, 20);
    row(r.muscle, "cadaver (stand-ins)", 1000 * timed(*cadaver), 0, 1000);
    const auto dense = model(r.muscle, DecompositionMethod::kSlicing, 256, 50);
    row(r.muscle, "slicing 256 x 50", 1000 * timed(*dense), 0, 150);
  }
  return rows;
}

void write_accuracy_table() {
  std::ostringstream out;
  const nlohmann::json quality = quality_table(out);
  const nlohmann::json speed = speed_table(out);
  std::cout << out.str();
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  const std::filesystem::path folder = out_dir != nullptr ? out_dir : ".";
  std::ofstream(folder / "fibres.accuracy.txt") << out.str();
  std::ofstream(folder / "fibres.accuracy.json")
      << nlohmann::json{{"quality", quality}, {"speed", speed}}.dump(2) << "\n";
}

void BM_Decompose(benchmark::State& state, const std::string& muscle, DecompositionMethod method) {
  const auto m = model(muscle, method, 81, 20);
  for (auto _ : state) benchmark::DoNotOptimize(m->decompose_at_rest());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK_CAPTURE(BM_Decompose, gluteus_medius_slicing, "gluteus_medius_r",
                  DecompositionMethod::kSlicing)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Decompose, gluteus_medius_harmonic, "gluteus_medius_r",
                  DecompositionMethod::kHarmonic)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Decompose, gluteus_medius_mass_spring, "gluteus_medius_r",
                  DecompositionMethod::kMassSpring)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Decompose, iliacus_slicing, "iliacus_r", DecompositionMethod::kSlicing)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Decompose, iliacus_harmonic, "iliacus_r", DecompositionMethod::kHarmonic)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Decompose, iliacus_mass_spring, "iliacus_r", DecompositionMethod::kMassSpring)
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return mmm::bench::run_suite(argc, argv, "mmm_bench_fibres", write_accuracy_table);
}

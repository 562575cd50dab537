// The volumetric pathway's model at rest: every muscle of the default atlas
// in one labelled lattice (core/volumetric/labelled_lattice.h), the bones
// carved out, overlaps split by depth, then six tetrahedra per cell
// (lattice_tets.h). (1) Per muscle and cell size: the segmentation's volume,
// what the grid itself changes, what the bones and the other muscles take,
// what regrowth gives back and how far out, and the volume kept (target:
// within 2 % of the segmentation). (2) Google
// Benchmark: the lattice and its tetrahedra at 3 mm; the simulation's set-up
// and one frame (fine lattice spacing, coarsening, rounds; nodes within 2 mm
// of a bone driven by it).
//
// The table goes to stdout and $MMM_BENCH_OUT_DIR/volumetric.accuracy.{txt,json}.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_main.h"
#include "core/atlas/atlas_io.h"
#include "core/atlas/atlas_meshes.h"
#include "core/mesh/aabb_tree.h"
#include "core/volumetric/labelled_lattice.h"
#include "core/volumetric/lattice_tets.h"
#include "core/volumetric/tet_simulation.h"

namespace {

namespace fs = std::filesystem;
using namespace mmm;

fs::path atlas_dir() {
  const char* dir = std::getenv("MMM_BENCH_ATLAS");
  return dir != nullptr ? dir : "build/atlas/vhf_right_leg";
}

struct Bodies {
  atlas::Atlas atlas;
  atlas::AtlasMeshes meshes;
  std::vector<volumetric::NamedSurface> muscles;
  std::vector<volumetric::NamedSurface> bones;
};

const Bodies& bodies() {
  static const Bodies data = [] {
    Bodies b;
    b.atlas = atlas::read_atlas(atlas_dir());
    b.meshes = atlas::read_atlas_meshes(b.atlas, atlas_dir());
    for (const atlas::Muscle& m : b.atlas.muscles) {
      b.muscles.push_back({m.name, &b.meshes.at(m.name).at("full")});
    }
    for (const atlas::Bone& bone : b.atlas.bones) {
      b.bones.push_back({bone.name, &b.meshes.at(bone.name).at("full")});
    }
    return b;
  }();
  return data;
}

double median(std::vector<double> values) {
  std::ranges::sort(values);
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

void write_accuracy_table() {
  const Bodies& b = bodies();
  std::ostringstream out;
  out << std::fixed;
  nlohmann::json document = nlohmann::json::array();
  for (const double spacing : {3.0, 2.0}) {
    const volumetric::LabelledLattice lattice = volumetric::build_labelled_lattice(
        b.muscles, b.bones, {.spacing_mm = spacing, .threads = 2});
    const volumetric::TetMesh tets = volumetric::lattice_tets(lattice);
    out << "\nlattice " << std::setprecision(1) << spacing << " mm: " << lattice.cells.x() << " x "
        << lattice.cells.y() << " x " << lattice.cells.z() << " cells, " << tets.V.rows()
        << " nodes, " << tets.T.rows() << " tetrahedra\n";
    out << std::left << std::setw(30) << "muscle" << std::right << std::setw(12) << "segm cm3"
        << std::setw(10) << "grid %" << std::setw(10) << "bones %" << std::setw(11) << "muscles %"
        << std::setw(11) << "regrown %" << std::setw(10) << "depth mm" << std::setw(10) << "kept %"
        << "\n";
    std::vector<double> changes;
    nlohmann::json rows = nlohmann::json::array();
    int within = 0;
    for (const volumetric::MuscleCells& m : lattice.muscles) {
      const double s = m.segmented_mm3;
      out << std::left << std::setw(30) << m.name << std::right << std::setprecision(1)
          << std::setw(12) << s / 1000.0 << std::setprecision(2) << std::setw(10)
          << 100.0 * (m.inside_mm3 / s - 1.0) << std::setw(10) << -100.0 * m.to_bones_mm3 / s
          << std::setw(11) << -100.0 * m.to_muscles_mm3 / s << std::setw(11)
          << 100.0 * m.regrown_mm3 / s << std::setprecision(1) << std::setw(10)
          << m.regrowth_depth_mm << std::setprecision(2) << std::setw(10) << 100.0 * m.change()
          << "\n";
      changes.push_back(std::abs(m.change()));
      within += std::abs(m.change()) <= 0.02 ? 1 : 0;
      rows.push_back({{"muscle", m.name},
                      {"segmented_mm3", s},
                      {"grid_change", m.inside_mm3 / s - 1.0},
                      {"to_bones", m.to_bones_mm3 / s},
                      {"to_muscles", m.to_muscles_mm3 / s},
                      {"regrown", m.regrown_mm3 / s},
                      {"regrowth_depth_mm", m.regrowth_depth_mm},
                      {"change", m.change()}});
    }
    out << "|change|: median " << std::setprecision(2) << 100.0 * median(changes) << " %, max "
        << 100.0 * *std::ranges::max_element(changes) << " %; within 2 %: " << within << " of "
        << changes.size() << "\n";
    document.push_back({{"spacing_mm", spacing},
                        {"nodes", tets.V.rows()},
                        {"tetrahedra", tets.T.rows()},
                        {"muscles", rows}});
  }
  std::cout << out.str();
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  const fs::path folder = out_dir != nullptr ? out_dir : ".";
  std::ofstream(folder / "volumetric.accuracy.txt") << out.str();
  std::ofstream(folder / "volumetric.accuracy.json") << document.dump(2) << "\n";
}

// Every atlas muscle into one lattice at 3 mm, bones carved out (2 threads).
void BM_LabelledLattice(benchmark::State& state) {
  const Bodies& b = bodies();
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        volumetric::build_labelled_lattice(b.muscles, b.bones, {.spacing_mm = 3.0, .threads = 2}));
  }
}
BENCHMARK(BM_LabelledLattice)->Unit(benchmark::kMillisecond);

// Its tetrahedra (six per cell).
void BM_LatticeTets(benchmark::State& state) {
  const Bodies& b = bodies();
  const volumetric::LabelledLattice lattice =
      volumetric::build_labelled_lattice(b.muscles, b.bones, {.spacing_mm = 3.0, .threads = 2});
  for (auto _ : state) benchmark::DoNotOptimize(volumetric::lattice_tets(lattice));
}
BENCHMARK(BM_LatticeTets)->Unit(benchmark::kMillisecond);

// The simulation on the atlas's lattice at `spacing` mm: nodes within 2 mm
// of a bone follow it (a stand-in for the attachments), every bone checked.
struct Simulated {
  volumetric::EmbeddedModel model;
  std::vector<volumetric::DrivenNode> driven;
  std::vector<const mesh::IndexedMesh*> bones;
};

Simulated simulated(double spacing, int factor) {
  const Bodies& b = bodies();
  Simulated out;
  out.model = volumetric::embed_in_coarse_lattice(
      volumetric::build_labelled_lattice(b.muscles, b.bones, {.spacing_mm = spacing, .threads = 2}),
      factor);
  for (const volumetric::NamedSurface& bone : b.bones) out.bones.push_back(bone.surface);
  std::vector<std::unique_ptr<mesh::AabbTree>> trees;
  for (const mesh::IndexedMesh* bone : out.bones)
    trees.push_back(std::make_unique<mesh::AabbTree>(*bone));
  const Eigen::MatrixX3d& nodes = out.model.output.V;
  for (Eigen::Index i = 0; i < nodes.rows(); ++i) {
    for (std::size_t k = 0; k < trees.size(); ++k) {
      if (trees[k]->closest_point_within(nodes.row(i).transpose(), 4.0)) {
        out.driven.push_back({static_cast<int>(i), static_cast<int>(k)});
        break;
      }
    }
  }
  return out;
}

// Setting up the simulation (factorisation, warm-start weights, contact
// candidates): fine lattice spacing (mm) and coarsening factor.
void BM_SimulationSetup(benchmark::State& state) {
  const Simulated s =
      simulated(static_cast<double>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) {
    volumetric::TetSimulation simulation(s.model, s.driven, s.bones, {.threads = 2});
    benchmark::DoNotOptimize(simulation.checked_nodes());
  }
  state.counters["element_nodes"] = static_cast<double>(s.model.elements.V.rows());
  state.counters["elements"] = static_cast<double>(s.model.elements.T.rows());
  state.counters["output_nodes"] = static_cast<double>(s.model.output.V.rows());
}
BENCHMARK(BM_SimulationSetup)
    ->Args({3, 1})
    ->Args({3, 2})
    ->Args({2, 3})
    ->Unit(benchmark::kMillisecond);

// One frame with the bones where they are (rounds: the third argument).
void BM_SimulationFrame(benchmark::State& state) {
  const Simulated s =
      simulated(static_cast<double>(state.range(0)), static_cast<int>(state.range(1)));
  volumetric::TetSimulation simulation(
      s.model, s.driven, s.bones, {.iterations = static_cast<int>(state.range(2)), .threads = 2});
  const std::vector<Eigen::Isometry3d> poses(s.bones.size(), Eigen::Isometry3d::Identity());
  volumetric::FrameStats last;
  for (auto _ : state) {
    last = simulation.step(poses);
    benchmark::DoNotOptimize(last.inverted);
  }
  state.counters["element_nodes"] = static_cast<double>(s.model.elements.V.rows());
  state.counters["checked"] = simulation.checked_nodes();
  state.counters["inverted"] = last.inverted;
  state.counters["bone_depth_mm"] = last.max_bone_depth_mm;
  state.counters["local_s"] = last.local_seconds;
  state.counters["contact_s"] = last.contact_seconds;
  state.counters["solve_s"] = last.solve_seconds;
  state.counters["volume_s"] = last.volume_seconds;
}
BENCHMARK(BM_SimulationFrame)
    ->Args({3, 1, 2})
    ->Args({3, 2, 2})
    ->Args({2, 3, 2})
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return mmm::bench::run_suite(argc, argv, "mmm_bench_volumetric", write_accuracy_table);
}

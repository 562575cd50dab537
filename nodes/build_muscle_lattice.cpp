#include "nodes/build_muscle_lattice.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/parallel_for.h"
#include "core/volumetric/labelled_lattice.h"
#include "core/volumetric/lattice_io.h"
#include "core/volumetric/lattice_tets.h"
#include "nodes/muscle_selection.h"

namespace mmm::nodes {
namespace {

constexpr double kVolumeTarget = 0.02;  // each muscle within 2 % of its segmentation

nlohmann::json muscle_row(const volumetric::MuscleCells& m, int label) {
  const double s = m.segmented_mm3;
  return {{"muscle", m.name},
          {"label", label},
          {"segmented_mm3", s},
          {"grid_change_percent", 100.0 * (m.inside_mm3 / s - 1.0)},
          {"to_bones_percent", 100.0 * m.to_bones_mm3 / s},
          {"to_muscles_percent", 100.0 * m.to_muscles_mm3 / s},
          {"regrown_percent", 100.0 * m.regrown_mm3 / s},
          {"regrowth_depth_mm", m.regrowth_depth_mm},
          {"kept_mm3", m.kept_mm3},
          {"change_percent", 100.0 * m.change()}};
}

}  // namespace

workflow::NodeSpec BuildMuscleLattice::spec() {
  using workflow::port::Atlas;
  using workflow::port::File;
  using workflow::port::Report;
  const volumetric::LatticeOptions d;
  return workflow::NodeSpec{
      "build_muscle_lattice", 1,
      "All muscles at rest as one conforming tetrahedral model for the volumetric pathway: a "
      "labelled lattice (bones carved out, overlapping segmentations resolved by depth, lost "
      "volume grown back on the free sides), six tetrahedra per cell, touching muscles sharing "
      "their interface nodes"}
      .resources(2, 4096)
      .input<Atlas>("atlas", "The (scaled) atlas")
      .param<double>("spacing_mm", d.spacing_mm,
                     "Cell edge (mm); 2 keeps every muscle of the default atlas within 1 % of "
                     "its volume, 3 within 2 %",
                     {.min = 0.5, .max = 20.0})
      .param<double>("max_regrowth_mm", d.max_regrowth_mm,
                     "How far beyond its cells a muscle may grow back the volume it gave to "
                     "another muscle or a bone (mm); 0: not grown back",
                     {.min = 0.0, .max = 50.0})
      .param<std::string>("muscles", "",
                          "Comma-separated muscle names; empty: every muscle of the atlas")
      .param<std::int64_t>("threads", 0, "Worker threads; 0: the machine's", {.min = 0, .max = 64})
      .output<File>("lattice",
                    "Folder bundle: lattice.json, muscles.lattice (binary labels, from which "
                    "the tetrahedra follow), muscles.vti (ParaView: colour by 'muscle')")
      .output<Report>("report",
                      "Per muscle: segmented volume and what the grid, the bones, the other "
                      "muscles and the regrowth changed (%); nodes, tetrahedra, time");
}

void BuildMuscleLattice::run(workflow::NodeContext& context) {
  const auto start = std::chrono::steady_clock::now();
  const std::filesystem::path atlas_dir = context.scratch_dir() / "atlas";
  unpack_directory(context.input_bytes("atlas"), atlas_dir, "input 'atlas'");
  const atlas::Atlas atlas = atlas::read_atlas(atlas_dir);
  const std::vector<const atlas::Muscle*> muscles =
      selected_muscles(atlas, context.text("muscles"), "build_muscle_lattice");
  context.progress(0, 3, "reading the surfaces");
  std::vector<mesh::IndexedMesh> surfaces;
  surfaces.reserve(muscles.size() + atlas.bones.size());
  for (const atlas::Muscle* m : muscles) surfaces.push_back(atlas::load_mesh(atlas_dir, m->meshes));
  for (const atlas::Bone& b : atlas.bones)
    surfaces.push_back(atlas::load_mesh(atlas_dir, b.meshes));
  std::vector<volumetric::NamedSurface> muscle_surfaces;
  std::vector<volumetric::NamedSurface> bone_surfaces;
  for (std::size_t m = 0; m < muscles.size(); ++m) {
    muscle_surfaces.push_back({muscles[m]->name, &surfaces[m]});
  }
  for (std::size_t b = 0; b < atlas.bones.size(); ++b) {
    bone_surfaces.push_back({atlas.bones[b].name, &surfaces[muscles.size() + b]});
  }
  volumetric::LatticeOptions options;
  options.spacing_mm = context.number("spacing_mm");
  options.max_regrowth_mm = context.number("max_regrowth_mm");
  const std::int64_t threads = context.integer("threads");
  options.threads = threads > 0 ? static_cast<int>(threads) : machine_threads();
  context.progress(1, 3, "labelling the lattice");
  const volumetric::LabelledLattice lattice =
      volumetric::build_labelled_lattice(muscle_surfaces, bone_surfaces, options);
  context.progress(2, 3, "tetrahedra");
  const volumetric::TetMesh tets = volumetric::lattice_tets(lattice);

  nlohmann::json rows = nlohmann::json::array();
  std::vector<std::string> off_target;
  double worst = 0.0;
  for (std::size_t m = 0; m < lattice.muscles.size(); ++m) {
    const volumetric::MuscleCells& cells = lattice.muscles[m];
    rows.push_back(muscle_row(cells, static_cast<int>(m + 1)));
    worst = std::max(worst, std::abs(cells.change()));
    if (std::abs(cells.change()) > kVolumeTarget) off_target.push_back(cells.name);
  }
  if (!off_target.empty()) {
    std::string names;
    for (const std::string& n : off_target) names += (names.empty() ? "" : ", ") + n;
    context.warn(std::to_string(off_target.size()) + " muscle(s) changed volume by more than " +
                 "2 % in the lattice (" + names +
                 "); a smaller spacing_mm or a larger max_regrowth_mm brings them closer");
  }
  const std::filesystem::path folder = context.scratch_dir() / "lattice";
  std::filesystem::create_directories(folder);
  volumetric::write_lattice(folder / "muscles.lattice", lattice);
  volumetric::write_lattice_vti(folder / "muscles.vti", lattice);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const nlohmann::json summary = {
      {"spacing_mm", lattice.spacing_mm},
      {"origin_mm", {lattice.origin.x(), lattice.origin.y(), lattice.origin.z()}},
      {"cells", {lattice.cells.x(), lattice.cells.y(), lattice.cells.z()}},
      {"max_regrowth_mm", options.max_regrowth_mm},
      {"nodes", tets.V.rows()},
      {"tetrahedra", tets.T.rows()},
      {"max_abs_change_percent", 100.0 * worst},
      {"muscles_over_2_percent", off_target.size()},
      {"muscles", rows}};
  std::ofstream(folder / "lattice.json") << summary.dump(2) << "\n";
  context.set_output("lattice", pack_directory(folder));
  nlohmann::json report = summary;
  report["seconds"] = seconds;
  report["threads"] = options.threads;
  context.set_output("report", report.dump(2));
  context.progress(3, 3, "done");
}

}  // namespace mmm::nodes

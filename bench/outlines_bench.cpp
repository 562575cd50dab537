// Outline fitting: accuracy of the patient's bones after fitting their
// outlines on the radiographs, beside landmark-only scaling, on patients the
// atlas cannot represent exactly — another person's bones (gait2392's,
// `mmm patient foreign`) and the atlas with local shape (torsion, bowing,
// bumps: `mmm patient synth --local-shape`) — and the time of the fit.
//
// Patients are made once under $MMM_BENCH_OUT_DIR/outline_patients_filled
// (reused when present), rendered as a real limb: soft tissue filling an
// envelope, the bones replacing it. Landmarks: the station's (femoral head,
// patella, ankle centres) at their true positions, so that what remains is
// the shape. Table on stdout and in outlines.accuracy.{txt,json}
// (bench/table.py folds it into build/bench/outlines.json).
//
// For studying the fit: MMM_BENCH_OUTLINE_PATIENTS ("foreign_201,local_301")
// picks patients, MMM_BENCH_OUTLINE_OPTIONS changes settings (see
// fit_options), MMM_BENCH_OUTLINE_BONES_ONLY renders patients without soft
// tissue (in outline_patients_bones_only/), MMM_BENCH_OUTLINE_MUSCLES_IN_AIR
// with the muscles as soft tissue in air (outline_patients_muscles_in_air/),
// MMM_BENCH_OUTLINE_VERBOSE prints each bone's fit, writes the overlays and
// fitted surfaces and counts the
// true surface's far vertices by height.

#include <benchmark/benchmark.h>

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
#include "core/atlas/atlas_meshes.h"
#include "core/atlas/bone_set_patient.h"
#include "core/atlas/foreign_bones.h"
#include "core/atlas/synthetic_patient.h"
#include "core/image/outline_overlay.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/surface_distance.h"
#include "core/outlines/atlas_outline_fit.h"
#include "core/scaling/atlas_scaling.h"

namespace {

namespace fs = std::filesystem;
using mmm::landmarks::LandmarkSet;
namespace scaling = mmm::scaling;
namespace outlines = mmm::outlines;

fs::path atlas_dir() {
  const char* dir = std::getenv("MMM_BENCH_ATLAS");
  return dir != nullptr ? dir : "build/atlas/vhf_right_leg";
}
fs::path out_dir() {
  const char* dir = std::getenv("MMM_BENCH_OUT_DIR");
  return dir != nullptr ? dir : "build/bench";
}

const std::vector<std::string> kMeasured = {"femur_r", "tibia_r", "fibula_r", "patella_r",
                                            "pelvis"};
const std::vector<std::string> kStation = {"femoral_head_centre_r", "patella_centre_r",
                                           "ankle_centre_r"};

struct Patient {
  std::string name;
  std::string kind;  // "foreign bones" | "local shape"
  fs::path dir;
  std::map<std::string, mmm::mesh::IndexedMesh> truth;  // measured bones
  LandmarkSet landmarks;
};

LandmarkSet station_landmarks(const nlohmann::json& truth) {
  LandmarkSet set;
  set.source = "ground truth";
  for (const std::string& name : kStation) {
    const auto& p = truth.at("landmarks").at(name).at("position_mm");
    set.landmarks.push_back(
        {name,
         Eigen::Vector3d(p[0].get<double>(), p[1].get<double>(), p[2].get<double>()),
         {},
         {}});
  }
  return set;
}

Patient make_patient(const std::string& kind, std::uint64_t seed) {
  Patient patient;
  patient.kind = kind;
  const bool foreign = kind == "foreign bones";
  patient.name = (foreign ? "foreign_" : "local_") + std::to_string(seed);
  const bool bones_only = std::getenv("MMM_BENCH_OUTLINE_BONES_ONLY") != nullptr;
  const bool in_air = std::getenv("MMM_BENCH_OUTLINE_MUSCLES_IN_AIR") != nullptr;
  const bool filled = !bones_only && !in_air;
  patient.dir = out_dir() /
                (bones_only ? "outline_patients_bones_only"
                 : in_air   ? "outline_patients_muscles_in_air"
                            : "outline_patients_filled") /
                patient.name;
  if (!fs::exists(patient.dir / "ground_truth.json")) {
    if (foreign) {
      mmm::atlas::ForeignBoneOptions options;
      options.deformation.seed = seed;
      options.deformation.local_shape = seed % 2 == 0;  // every other one with local shape too
      mmm::atlas::BoneSet set = mmm::atlas::gait2392_bone_set(atlas_dir(), MMM_DATA_DIR, options);
      if (bones_only) set.soft_tissue.clear();
      mmm::atlas::PatientRadiographOptions pictures;
      pictures.seed = seed;
      pictures.soft_tissue_envelope = filled;
      mmm::atlas::make_bone_set_patient(set, atlas_dir(), patient.dir, pictures);
    } else {
      mmm::atlas::SyntheticPatientOptions options;
      options.deformation.seed = seed;
      options.deformation.local_shape = true;
      options.soft_tissue_envelope = filled;
      if (bones_only) options.mu_soft_per_mm = 0.0;  // the muscles drawn at 0: bones alone
      mmm::atlas::make_synthetic_patient(atlas_dir(), patient.dir, options);
    }
  }
  std::ifstream in(patient.dir / "ground_truth.json");
  const nlohmann::json truth = nlohmann::json::parse(in);
  patient.landmarks = station_landmarks(truth);
  for (const std::string& bone : kMeasured) {
    patient.truth[bone] =
        mmm::mesh::read_mesh(foreign ? patient.dir / "bones" / (bone + ".ply")
                                     : patient.dir / "atlas" / "meshes" / bone / "full.ply");
  }
  return patient;
}

struct Row {
  std::string patient;
  std::string kind;
  std::map<std::string, mmm::mesh::SurfaceDistance> scaled;
  std::map<std::string, mmm::mesh::SurfaceDistance> fitted;
  double fit_seconds = 0.0;
  std::map<std::string, double> held;
};

std::vector<std::pair<std::string, std::uint64_t>> patient_list() {
  std::vector<std::pair<std::string, std::uint64_t>> list;
  for (std::uint64_t seed = 201; seed <= 206; ++seed) list.emplace_back("foreign bones", seed);
  for (std::uint64_t seed = 301; seed <= 303; ++seed) list.emplace_back("local shape", seed);
  if (const char* only = std::getenv("MMM_BENCH_OUTLINE_PATIENTS")) {
    // e.g. "foreign_201,local_301"
    std::vector<std::pair<std::string, std::uint64_t>> kept;
    const std::string wanted = std::string(",") + only + ",";
    for (const auto& [kind, seed] : list) {
      const std::string name =
          (kind == "foreign bones" ? "foreign_" : "local_") + std::to_string(seed);
      if (wanted.find("," + name + ",") != std::string::npos) kept.emplace_back(kind, seed);
    }
    list = kept;
  }
  return list;
}

// The fit's options; MMM_BENCH_OUTLINE_OPTIONS ("spacing=10,smooth=2,...")
// changes them, to study one setting.
outlines::AtlasOutlineFitOptions fit_options() {
  outlines::AtlasOutlineFitOptions options;
  const char* text = std::getenv("MMM_BENCH_OUTLINE_OPTIONS");
  if (text == nullptr) return options;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) continue;
    const std::string key = item.substr(0, eq);
    const double value = std::stod(item.substr(eq + 1));
    if (key == "spacing") options.fit.node_spacing_mm = value;
    if (key == "smooth") options.fit.smoothness_weight = value;
    if (key == "prior") options.fit.prior_weight = value;
    if (key == "bending") options.fit.bending_weight = value;
    if (key == "pelvis_membrane") {
      for (const char* bone : {"pelvis", "pelvis_l", "sacrum"})
        options.membrane_factor[bone] = value;
    }
    if (key == "patella" && value != 0) options.bones.emplace_back("patella_r");
    if (key == "affine") options.fit.affine_weight = value;
    if (key == "robust") options.fit.robust_mm = value;
    if (key == "fall") options.fit.min_fall_factor = value;
    if (key == "neighbours") options.fit.node_neighbours = static_cast<int>(value);
    if (key == "joint") options.joint_pin = value;
    if (key == "nearness") options.fit.nearness = value;
    if (key == "thick") options.fit.thickness.weight = value;
    if (key == "thickfrom") options.fit.thickness.first_stage = static_cast<int>(value);
    if (key == "thickstep") options.fit.thickness.step_mm = value;
    if (key == "thickmargin") options.fit.thickness.margin_mm = value;
    if (key == "thickcos") options.fit.thickness.min_cosine = value;
    if (key == "thickcut") options.fit.thickness.cutoff = value;
    if (key == "thickrefresh") options.fit.thickness.refresh_gain = value != 0;
    if (key == "thickrobust") options.fit.thickness.robust_mm = value;
    if (key == "softmodel") options.soft_tissue_model = value != 0;
    if (key == "softfat") options.soft_tissue.fat_mm = value;
    if (key == "softskin") options.soft_tissue.skin_margin_mm = value;
    if (key == "softoutline") options.soft_tissue.fit_outline = value != 0;
    if (key == "pelvis_free" && value != 0)
      options.tissue_free_bones = {"pelvis", "pelvis_l", "sacrum"};
    if (key == "all_free" && value != 0)
      options.tissue_free_bones = {"pelvis",  "pelvis_l", "sacrum",
                                   "femur_r", "tibia_r",  "fibula_r"};
    if (key == "after" && value == 0) options.rounds.clear();
    if (key == "after" && value == 2) options.rounds = {{"*"}, {"tibia_r"}};
    if (key == "after" && value == 3) options.rounds = {{"*"}, {"pelvis"}};
    if (key == "after" && value == 4)
      options.rounds = {{"*", "tibia_r"}, {"fibula_r"}, {"tibia_r"}};
    if (key == "after" && value == 5) options.rounds = {{"*", "tibia_r"}, {"fibula_r"}};
    if (key == "after" && value == 6) options.rounds = {{"*", "tibia_r"}, {"fibula_r", "pelvis"}};
    if (key == "after" && value == 7) options.rounds = {{"*"}, {"fibula_r", "patella_r"}};
    if (key == "fibula_spacing") options.node_spacing_mm["fibula_r"] = value;
    if (key == "tibia_spacing") options.node_spacing_mm["tibia_r"] = value;
    if (key == "pelvis_spacing") options.node_spacing_mm["pelvis"] = value;
    if (key == "rpelvis_thick") options.thickness_factor["pelvis"] = value;
    if (key == "pelvis_thick") {
      for (const char* bone : {"pelvis", "pelvis_l", "sacrum"})
        options.thickness_factor[bone] = value;
    }
    if (key == "sigma0") options.fit.stages[0].sigma_px = value;
    if (key.starts_with("sf"))
      options.fit.stages.at(std::stoul(key.substr(2))).smoothness_factor = value;
    if (key.starts_with("reach")) options.fit.stages.at(std::stoul(key.substr(5))).reach_mm = value;
    if (key.starts_with("it")) {
      options.fit.stages.at(std::stoul(key.substr(2))).iterations = static_cast<int>(value);
    }
  }
  return options;
}

struct Loaded {
  mmm::atlas::Atlas atlas;
  std::shared_ptr<const scaling::PreparedAtlas> prepared;
};

const Loaded& loaded() {
  static const Loaded data = [] {
    Loaded l;
    l.atlas = mmm::atlas::read_atlas(atlas_dir());
    l.prepared =
        scaling::prepare_atlas(l.atlas, mmm::atlas::read_atlas_meshes(l.atlas, atlas_dir()));
    return l;
  }();
  return data;
}

Row measure(const Patient& patient) {
  const Loaded& l = loaded();
  const scaling::ScaledAtlas scaled = scaling::scale_atlas(*l.prepared, patient.landmarks);
  const mmm::image::RadiographPair pair =
      mmm::image::load_radiograph_pair(patient.dir / "radiographs" / "views.json");
  const auto start = std::chrono::steady_clock::now();
  const outlines::AtlasOutlineFit fit = outlines::fit_atlas_outlines(
      scaled.atlas, scaled.meshes, patient.landmarks, pair, {}, fit_options());
  Row row;
  row.patient = patient.name;
  row.kind = patient.kind;
  row.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (std::getenv("MMM_BENCH_OUTLINE_VERBOSE") != nullptr) {
    std::cerr << patient.name << " images and soft tissue " << fit.images_seconds << " s, fit "
              << fit.fit_seconds << " s\n";
    for (const outlines::SoftTissueLaw& law : fit.soft_tissue) {
      std::cerr << patient.name << " soft tissue " << law.view << (law.used ? "" : " (not used)")
                << ": offset " << law.offset << ", tissue " << law.tissue_per_mm << "/mm, muscle "
                << law.muscle_per_mm << "/mm, " << law.samples << " pixels, rms "
                << law.residual_rms << ", outline rows " << law.rows_matched << ", width ratio "
                << law.median_width_ratio << "\n";
    }
    std::vector<mmm::mesh::IndexedMesh> shown;
    shown.reserve(2 * fit.bones.size() + kMeasured.size());
    std::vector<mmm::image::OutlineItem> items;
    for (const outlines::BoneOutlineFit& b : fit.bones) {
      shown.push_back(scaled.meshes.at(b.bone).at("full"));
      items.push_back({b.bone, &shown.back(), {255, 60, 60}});
      shown.push_back({b.vertices, scaled.meshes.at(b.bone).at("full").F});
      items.push_back({b.bone, &shown.back(), {60, 255, 60}});
    }
    for (const std::string& bone : kMeasured)
      items.push_back({bone, &patient.truth.at(bone), {60, 120, 255}});
    mmm::image::OverlayOptions overlay;
    overlay.max_width = 3000;
    overlay.line_width_px = 1.0;
    mmm::image::write_png(mmm::image::outline_overlay_pair(pair, items, overlay),
                          out_dir() / (patient.name + "_outlines.png"));
  }
  for (const std::string& bone : kMeasured) {
    row.scaled[bone] =
        mmm::mesh::surface_distance(scaled.meshes.at(bone).at("full"), patient.truth.at(bone));
    for (const outlines::BoneOutlineFit& b : fit.bones) {
      if (b.bone != bone) continue;
      mmm::mesh::IndexedMesh fitted{b.vertices, scaled.meshes.at(bone).at("full").F};
      row.fitted[bone] = mmm::mesh::surface_distance(fitted, patient.truth.at(bone));
      row.held[bone] = b.held_by_prior;
      if (std::getenv("MMM_BENCH_OUTLINE_VERBOSE") != nullptr) {
        mmm::mesh::write_mesh(fitted, out_dir() / (patient.name + "_" + bone + "_fitted.ply"));
        const mmm::mesh::AabbTree tree(fitted);
        const Eigen::VectorXd d = mmm::mesh::distances_to_surface(patient.truth.at(bone).V, tree);
        // Far truth vertices by height band.
        std::map<int, std::pair<int, int>> bands;
        for (Eigen::Index i = 0; i < d.size(); ++i) {
          auto& band = bands[static_cast<int>(std::floor(patient.truth.at(bone).V(i, 2) / 20.0))];
          ++band.second;
          if (d[i] > 5.0) ++band.first;
        }
        std::cerr << "  " << bone << " far (>5 mm) by 20 mm band:";
        for (const auto& [z, c] : bands)
          std::cerr << " " << z * 20 << ":" << c.first << "/" << c.second;
        std::cerr << "\n";
      }
      if (std::getenv("MMM_BENCH_OUTLINE_VERBOSE") != nullptr) {
        std::cerr << patient.name << " " << bone << ": nodes " << b.nodes << ", iterations "
                  << b.iterations << (b.converged ? " converged" : "") << ", last change "
                  << b.last_change_mm << " mm (p95 " << b.last_change_p95_mm << "), " << b.seconds
                  << " s, moved " << b.moved_mean_mm << " / " << b.moved_max_mm << " mm, held "
                  << b.held_by_prior;
        for (const auto& v : b.views) {
          std::cerr << " | " << v.view << " " << v.matched << "/" << v.contour_points << " "
                    << v.start_mean_mm << " -> " << v.mean_mm << " (p95 " << v.p95_mm << ")"
                    << " thickness " << v.thickness_samples << " rays, mean " << v.thickness_mean_mm
                    << " mm, gain " << v.thickness_gain;
          for (const int px : b.neighbours_removed_px) std::cerr << " | neighbours " << px << " px";
        }
        std::cerr << "\n";
      }
    }
  }
  return row;
}

void write_accuracy_table() {
  std::vector<Row> rows;
  for (const auto& [kind, seed] : patient_list()) rows.push_back(measure(make_patient(kind, seed)));
  std::ostringstream text;
  text << std::fixed << std::setprecision(2);
  text << "Outline fitting vs landmark-only scaling (station landmarks, exact); surface distance "
          "to the true bone, mean / p95 / max (mm)\n";
  text << std::left << std::setw(13) << "patient" << std::setw(14) << "kind";
  for (const std::string& bone : kMeasured) text << std::setw(36) << bone;
  text << "fit s\n";
  nlohmann::json json = nlohmann::json::array();
  for (const Row& row : rows) {
    text << std::left << std::setw(13) << row.patient << std::setw(14) << row.kind;
    nlohmann::json entry = {
        {"patient", row.patient}, {"kind", row.kind}, {"fit_seconds", row.fit_seconds}};
    for (const std::string& bone : kMeasured) {
      const auto& s = row.scaled.at(bone);
      std::ostringstream cell;
      cell << std::fixed << std::setprecision(2) << s.mean_mm;
      if (row.fitted.contains(bone)) {
        const auto& f = row.fitted.at(bone);
        cell << " -> " << f.mean_mm << "/" << f.p95_mm << "/" << f.max_mm;
        entry["bones"][bone] = {{"scaled_mean_mm", s.mean_mm},       {"scaled_p95_mm", s.p95_mm},
                                {"scaled_max_mm", s.max_mm},         {"fitted_mean_mm", f.mean_mm},
                                {"fitted_p95_mm", f.p95_mm},         {"fitted_max_mm", f.max_mm},
                                {"held_by_prior", row.held.at(bone)}};
      }
      text << std::setw(36) << cell.str();
    }
    text << std::setprecision(1) << row.fit_seconds << std::setprecision(2) << "\n";
    json.push_back(entry);
  }
  std::cout << text.str();
  fs::create_directories(out_dir());
  std::ofstream(out_dir() / "outlines.accuracy.txt") << text.str();
  std::ofstream(out_dir() / "outlines.accuracy.json") << json.dump(2) << '\n';
}

void BM_FitWholeLeg(benchmark::State& state) {
  const std::vector<std::pair<std::string, std::uint64_t>> list = patient_list();
  const Patient patient = make_patient(list.front().first, list.front().second);
  const Loaded& l = loaded();
  const scaling::ScaledAtlas scaled = scaling::scale_atlas(*l.prepared, patient.landmarks);
  const mmm::image::RadiographPair pair =
      mmm::image::load_radiograph_pair(patient.dir / "radiographs" / "views.json");
  const outlines::AtlasOutlineFitOptions options = fit_options();
  for (auto _ : state) {
    benchmark::DoNotOptimize(outlines::fit_atlas_outlines(scaled.atlas, scaled.meshes,
                                                          patient.landmarks, pair, {}, options));
  }
}
BENCHMARK(BM_FitWholeLeg)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

int main(int argc, char** argv) {
  return mmm::bench::run_suite(argc, argv, "mmm_bench_outlines", write_accuracy_table);
}

// Atlas scaling (issue 6): accuracy over synthetic patients against their
// ground truth, beside the uniform-scaling baseline; the real-data check
// against OpenSim's scale factors for subject01; and the speed of scaling
// the whole default atlas (Google Benchmark, medians over repetitions).
//
// The atlas: $MMM_BENCH_ATLAS (bench/run builds the default one when
// missing). The accuracy table goes to stdout and, as JSON, to
// $MMM_BENCH_OUT_DIR/scaling.accuracy.json, which bench/table.py folds into
// build/bench/scaling.json.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_main.h"
#include "core/atlas/atlas_io.h"
#include "core/atlas/atlas_meshes.h"
#include "core/atlas/patient_deformation.h"
#include "core/landmarks/static_trial_landmarks.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/signed_distance.h"
#include "core/mesh/surface_distance.h"
#include "core/opensim/osim_model.h"
#include "core/opensim/trc.h"
#include "core/parallel_for.h"
#include "core/scaling/atlas_scaling.h"
#include "core/scaling/local_field.h"

namespace {

using mmm::atlas::AtlasMeshes;
using mmm::landmarks::LandmarkSet;
namespace scaling = mmm::scaling;

std::filesystem::path atlas_dir() {
  const char* dir = std::getenv("MMM_BENCH_ATLAS");
  return dir != nullptr ? dir : "build/atlas/vhf_right_leg";
}

struct Loaded {
  mmm::atlas::Atlas atlas;
  AtlasMeshes meshes;
  std::shared_ptr<const scaling::PreparedAtlas> prepared;
};

const Loaded& loaded() {
  static const Loaded data = [] {
    Loaded l;
    l.atlas = mmm::atlas::read_atlas(atlas_dir());
    l.meshes = mmm::atlas::read_atlas_meshes(l.atlas, atlas_dir());
    l.prepared = scaling::prepare_atlas(l.atlas, l.meshes);
    return l;
  }();
  return data;
}

// The station's three landmarks, and the station's plus the bony landmarks
// a markup import could add.
const std::vector<std::string> kStation = {"femoral_head_centre_r", "patella_centre_r",
                                           "ankle_centre_r"};
// $MMM_BENCH_BONY (comma-separated) replaces the bony set, to study one
// landmark's effect.
std::vector<std::string> bony_landmarks() {
  const char* given = std::getenv("MMM_BENCH_BONY");
  if (given == nullptr) {
    return {"asis_r",
            "asis_l",
            "sacral_point",
            "lateral_epicondyle_r",
            "medial_epicondyle_r",
            "lateral_malleolus_r",
            "medial_malleolus_r",
            "heel_r"};
  }
  std::vector<std::string> names;
  std::string text = given;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    if (comma > start) names.push_back(text.substr(start, comma - start));
    start = comma + 1;
  }
  return names;
}
const std::vector<std::string> kBony = bony_landmarks();

LandmarkSet landmark_set(const mmm::atlas::Atlas& truth, const std::vector<std::string>& names) {
  LandmarkSet set;
  set.source = "synthetic ground truth";
  for (const std::string& name : names) {
    const mmm::atlas::Landmark* landmark = truth.find_landmark(name);
    if (landmark != nullptr) set.landmarks.push_back({name, landmark->position, {}, {}});
  }
  return set;
}

struct Truth {
  mmm::atlas::Atlas atlas;
  AtlasMeshes meshes;  // full levels only
};

Truth make_truth(const Loaded& l, std::uint64_t seed, double height_mm) {
  mmm::atlas::PatientOptions options;
  options.seed = seed;
  options.height_mm = height_mm;
  const mmm::atlas::PatientDeformation deformation =
      mmm::atlas::make_patient_deformation(l.atlas, options);
  Truth truth;
  truth.atlas = mmm::atlas::deform_atlas(l.atlas, deformation);
  std::map<std::string, mmm::mesh::IndexedMesh> blend;
  for (const mmm::atlas::Bone& bone : l.atlas.bones) {
    blend[bone.name] = l.meshes.at(bone.name).at(bone.meshes.back().level);
    truth.meshes[bone.name]["full"] =
        mmm::atlas::deform_bone_mesh(deformation, bone.name, l.meshes.at(bone.name).at("full"));
  }
  std::vector<mmm::mesh::IndexedMesh> muscles(l.atlas.muscles.size());
  mmm::parallel_for(muscles.size(), 2, [&](std::size_t m) {
    muscles[m] = mmm::atlas::deform_muscle_mesh(deformation, blend,
                                                l.meshes.at(l.atlas.muscles[m].name).at("full"),
                                                options.blend_radius_mm);
  });
  for (std::size_t m = 0; m < muscles.size(); ++m) {
    truth.meshes[l.atlas.muscles[m].name]["full"] = std::move(muscles[m]);
  }
  return truth;
}

// The uniform baseline: one similarity for everything.
AtlasMeshes uniform_meshes(const Loaded& l, const scaling::ScalingEstimate& estimate) {
  AtlasMeshes out;
  const Eigen::Affine3d& map = estimate.deformation.bone_maps.begin()->second;
  for (const auto& [element, levels] : l.meshes) {
    mmm::mesh::IndexedMesh mapped = levels.at("full");
    mapped.V = (mapped.V * map.linear().transpose()).rowwise() + map.translation().transpose();
    out[element]["full"] = std::move(mapped);
  }
  return out;
}

struct Accuracy {
  double bone_mean_mm = 0;  // area-weighted over every bone surface
  double bone_worst_p95_mm = 0;
  double muscle_mean_mm = 0;  // area-weighted over every muscle surface
  double muscle_worst_p95_mm = 0;
  double landmark_max_mm = 0;
  double volume_max_percent = 0;  // largest |scaled / true volume - 1|, over muscles
  double penetration_max_mm = 0;  // new penetration of a muscle into a bone (new_penetration)
  std::map<std::string, double> per_bone_mean_mm;
};

// Deepest new penetration of any muscle vertex into any scaled bone (mm),
// checked independently of the scaling's own bookkeeping: every muscle
// vertex inside a bone's box (+1 mm) is tested; its depth beyond its depth
// at rest, scaled with the bone (cube root of the volume ratio), is new.
double new_penetration(const Loaded& l, const AtlasMeshes& scaled) {
  std::vector<double> worst(l.atlas.bones.size(), 0.0);
  mmm::parallel_for(l.atlas.bones.size(), 2, [&](std::size_t b) {
    const std::string& bone = l.atlas.bones[b].name;
    const mmm::mesh::IndexedMesh& placed = scaled.at(bone).at("full");
    const mmm::mesh::IndexedMesh& rest = l.meshes.at(bone).at("full");
    const mmm::mesh::SignedDistance now(placed);
    const mmm::mesh::SignedDistance before(rest);
    const double scale =
        std::cbrt(mmm::mesh::signed_volume(placed) / mmm::mesh::signed_volume(rest));
    Eigen::AlignedBox3d box(placed.V.colwise().minCoeff().transpose(),
                            placed.V.colwise().maxCoeff().transpose());
    box.extend(box.min() - Eigen::Vector3d::Constant(1.0));
    box.extend(box.max() + Eigen::Vector3d::Constant(1.0));
    for (const auto& muscle : l.atlas.muscles) {
      const Eigen::MatrixX3d& V = scaled.at(muscle.name).at("full").V;
      const Eigen::MatrixX3d& V0 = l.meshes.at(muscle.name).at("full").V;
      for (Eigen::Index i = 0; i < V.rows(); ++i) {
        const Eigen::Vector3d x = V.row(i).transpose();
        if (!box.contains(x)) continue;
        const double depth = -now.at(x);
        if (depth <= 0.0) continue;
        const double rest_depth = std::max(0.0, -before.at(Eigen::Vector3d(V0.row(i).transpose())));
        worst[b] = std::max(worst[b], depth - scale * rest_depth);
      }
    }
  });
  return *std::max_element(worst.begin(), worst.end());
}

Accuracy measure(const Loaded& l, const Truth& truth, const AtlasMeshes& scaled,
                 const LandmarkSet& set, const std::map<std::string, double>& residuals) {
  Accuracy a;
  std::vector<std::string> elements;
  for (const auto& bone : l.atlas.bones) elements.push_back(bone.name);
  for (const auto& muscle : l.atlas.muscles) elements.push_back(muscle.name);
  std::vector<mmm::mesh::SurfaceDistance> distance(elements.size());
  mmm::parallel_for(elements.size(), 2, [&](std::size_t e) {
    distance[e] = mmm::mesh::surface_distance(scaled.at(elements[e]).at("full"),
                                              truth.meshes.at(elements[e]).at("full"));
  });
  double bone_area = 0;
  double muscle_area = 0;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const bool is_bone = e < l.atlas.bones.size();
    const double area = mmm::mesh::surface_area(truth.meshes.at(elements[e]).at("full"));
    if (is_bone) {
      a.bone_mean_mm += area * distance[e].mean_mm;
      bone_area += area;
      a.bone_worst_p95_mm = std::max(a.bone_worst_p95_mm, distance[e].p95_mm);
      a.per_bone_mean_mm[elements[e]] = distance[e].mean_mm;
    } else {
      a.muscle_mean_mm += area * distance[e].mean_mm;
      muscle_area += area;
      a.muscle_worst_p95_mm = std::max(a.muscle_worst_p95_mm, distance[e].p95_mm);
      const double ratio = mmm::mesh::signed_volume(scaled.at(elements[e]).at("full")) /
                           mmm::mesh::signed_volume(truth.meshes.at(elements[e]).at("full"));
      a.volume_max_percent = std::max(a.volume_max_percent, 100.0 * std::abs(ratio - 1.0));
    }
  }
  a.bone_mean_mm /= bone_area;
  a.penetration_max_mm = new_penetration(l, scaled);
  a.muscle_mean_mm /= muscle_area;
  for (const auto& landmark : set.landmarks) {
    const auto found = residuals.find(landmark.name);
    if (found != residuals.end()) a.landmark_max_mm = std::max(a.landmark_max_mm, found->second);
  }
  return a;
}

nlohmann::json to_json(const Accuracy& a) {
  return {{"bone_mean_mm", a.bone_mean_mm},
          {"bone_worst_p95_mm", a.bone_worst_p95_mm},
          {"muscle_mean_mm", a.muscle_mean_mm},
          {"muscle_worst_p95_mm", a.muscle_worst_p95_mm},
          {"landmark_max_mm", a.landmark_max_mm},
          {"volume_max_percent", a.volume_max_percent},
          {"penetration_max_mm", a.penetration_max_mm},
          {"per_bone_mean_mm", a.per_bone_mean_mm}};
}

std::string fixed(double value, int decimals) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(decimals) << value;
  return text.str();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// gait2392's femur (hip to knee centre at full extension) and tibia (knee
// to ankle centre) lengths in mm.
std::pair<double, double> gait2392_segment_lengths(const mmm::opensim::OsimModel& model) {
  const mmm::opensim::Joint* hip = model.find_joint("hip_r");
  const mmm::opensim::Joint* knee = model.find_joint("knee_r");
  const mmm::opensim::Joint* ankle = model.find_joint("ankle_r");
  if (hip == nullptr || knee == nullptr || ankle == nullptr) return {0.0, 0.0};
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (const mmm::opensim::TransformAxis& axis : knee->spatial_transform) {
    if (axis.name.starts_with("translation")) shift += axis.axis * axis.function.evaluate(0.0);
  }
  const Eigen::Vector3d knee_in_femur = knee->parent.to_body(shift);
  const Eigen::Vector3d hip_in_femur = hip->child.to_body(Eigen::Vector3d::Zero());
  const Eigen::Vector3d knee_in_tibia = knee->child.to_body(Eigen::Vector3d::Zero());
  const Eigen::Vector3d ankle_in_tibia = ankle->parent.to_body(Eigen::Vector3d::Zero());
  return {1000.0 * (knee_in_femur - hip_in_femur).norm(),
          1000.0 * (ankle_in_tibia - knee_in_tibia).norm()};
}

nlohmann::json real_data_check(std::ostream& out) {
  const std::filesystem::path data = MMM_DATA_DIR;
  const auto pipelines = data / "gait2392" / "Pipelines";
  const auto result = mmm::landmarks::landmarks_from_static_trial(
      mmm::opensim::read_trc(pipelines / "subject01_static.trc"));
  const auto [femur_mm, tibia_mm] = gait2392_segment_lengths(
      mmm::opensim::read_osim(data / "gait2392" / "gait2392_thelen2003muscle.osim"));
  const auto at = [&](const char* name) { return result.landmarks.find(name)->position_mm; };
  const double thigh = (at("knee_centre_r") - at("femoral_head_centre_r")).norm();
  const double shank = (at("ankle_centre_r") - at("knee_centre_r")).norm();
  const double femur = thigh / femur_mm;
  const double tibia = shank / tibia_mm;
  out << "\nreal data: subject01_static.trc landmarks vs OpenSim's scale set (gait2392 generic)\n"
      << "  femur_r: hip-knee " << fixed(thigh, 1) << " mm / generic " << fixed(femur_mm, 1)
      << " mm = " << fixed(femur, 3) << " (OpenSim 1.147, "
      << fixed(100.0 * (femur / 1.14724 - 1.0), 1) << " %)\n"
      << "  tibia_r: knee-ankle " << fixed(shank, 1) << " mm / generic " << fixed(tibia_mm, 1)
      << " mm = " << fixed(tibia, 3) << " (OpenSim 0.989, "
      << fixed(100.0 * (tibia / 0.988523 - 1.0), 1) << " %)\n";
  return {{"femur_r", {{"ours", femur}, {"opensim", 1.14724}, {"thigh_mm", thigh}}},
          {"tibia_r", {{"ours", tibia}, {"opensim", 0.988523}, {"shank_mm", shank}}}};
}

void landmark_set_table(std::ostream& out, nlohmann::json& document);

void accuracy_table(std::ostream& out) {
  const Loaded& l = loaded();
  if (std::getenv("MMM_BENCH_SETS_ONLY") != nullptr) {
    nlohmann::json document;
    landmark_set_table(std::cout, document);  // as it goes: the runs take minutes
    const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
    std::ofstream file(std::filesystem::path(out_dir != nullptr ? out_dir : ".") /
                       "scaling.landmark_sets.json");
    file << document.dump(2) << "\n";
    return;
  }
  const int patients = std::getenv("MMM_BENCH_PATIENTS") != nullptr
                           ? std::atoi(std::getenv("MMM_BENCH_PATIENTS"))
                           : 10;
  // Each method: a name, the landmarks it is given, whether it is ours.
  struct Method {
    std::string name;
    std::vector<std::string> landmarks;
    bool ours = true;
  };
  const auto plus = [](std::vector<std::string> names, const std::vector<std::string>& more) {
    names.insert(names.end(), more.begin(), more.end());
    return names;
  };
  const std::vector<Method> method_list = {
      {"ours: station (H,P,A)", kStation, true},
      {"ours: station + ASIS", plus(kStation, {"asis_r", "asis_l"}), true},
      {"ours: station + bony", plus(kStation, kBony), true},
      {"uniform baseline (H,P,A)", kStation, false}};
  std::vector<std::string> methods;
  methods.reserve(method_list.size());
  for (const Method& method : method_list) methods.push_back(method.name);
  std::map<std::string, std::vector<Accuracy>> results;
  nlohmann::json per_patient = nlohmann::json::array();
  for (int p = 0; p < patients; ++p) {
    const std::uint64_t seed = 101 + static_cast<std::uint64_t>(p);
    const double height = 1500.0 + 550.0 * p / std::max(1, patients - 1);
    const Truth truth = make_truth(l, seed, height);
    nlohmann::json row = {{"seed", seed}, {"height_mm", height}};
    std::map<std::string, double> last_residuals;
    nlohmann::json last_report;
    for (const Method& method : method_list) {
      const LandmarkSet set = landmark_set(truth.atlas, method.landmarks);
      Accuracy a;
      if (!method.ours) {
        const scaling::ScalingEstimate estimate = scaling::estimate_uniform_scaling(l.atlas, set);
        a = measure(l, truth, uniform_meshes(l, estimate), set, estimate.landmark_residual_mm);
      } else {
        const scaling::ScaledAtlas scaled = scaling::scale_atlas(*l.prepared, set);
        a = measure(l, truth, scaled.meshes, set, scaled.landmark_residual_mm);
        last_residuals = scaled.landmark_residual_mm;
        last_report = scaling::scaling_report_json(scaled);
      }
      row[method.name] = to_json(a);
      if (method.ours) row[method.name]["landmark_residual_mm"] = last_residuals;
      results[method.name].push_back(a);
    }
    if (p == 0) row["report_of_ours_with_bony_landmarks"] = last_report;
    per_patient.push_back(row);
    std::cerr << "patient " << p + 1 << "/" << patients << " done\n";
  }
  const auto column = [&](const std::string& method, double Accuracy::*field, bool worst) {
    std::vector<double> values;
    for (const Accuracy& a : results[method]) values.push_back(a.*field);
    return worst ? *std::max_element(values.begin(), values.end()) : median(values);
  };
  struct Row {
    const char* label;
    double Accuracy::*field;
    const char* target;
  };
  const std::vector<Row> rows = {
      {"landmark residual, max (mm)", &Accuracy::landmark_max_mm, "<= 0.5"},
      {"bone surface mean (mm)", &Accuracy::bone_mean_mm, "<= 1.5"},
      {"bone worst p95 (mm)", &Accuracy::bone_worst_p95_mm, ""},
      {"muscle surface mean (mm)", &Accuracy::muscle_mean_mm, "<= 2"},
      {"muscle worst p95 (mm)", &Accuracy::muscle_worst_p95_mm, ""},
      {"muscle volume vs truth, max |%|", &Accuracy::volume_max_percent, ""},
      {"new penetration, max (mm)", &Accuracy::penetration_max_mm, "<= 0.5"}};
  out << "\nscaling accuracy over " << patients
      << " synthetic patients (seeds 101.., statures 1500-2050 mm), exact landmarks;\n"
      << "each cell: median over patients / worst patient\n";
  out << std::left << std::setw(34) << "metric";
  for (const std::string& method : methods) out << " " << std::setw(24) << method;
  out << " target\n";
  nlohmann::json table = nlohmann::json::array();
  for (const Row& row : rows) {
    nlohmann::json entry = {{"metric", row.label}, {"target", row.target}};
    out << std::setw(34) << row.label;
    for (const std::string& method : methods) {
      const double med = column(method, row.field, false);
      const double worst = column(method, row.field, true);
      out << " " << std::setw(24) << fixed(med, 3) + " / " + fixed(worst, 3);
      entry[method] = {{"median", med}, {"worst", worst}};
    }
    out << " " << row.target << "\n";
    table.push_back(entry);
  }
  // Per bone, ours with the station landmarks: where the error is.
  out << "per-bone mean surface distance, ours (station), median over patients (mm):\n ";
  for (const auto& bone : l.atlas.bones) {
    std::vector<double> values;
    for (const Accuracy& a : results[methods[0]])
      values.push_back(a.per_bone_mean_mm.at(bone.name));
    out << " " << bone.name << " " << fixed(median(values), 2);
  }
  out << "\n";
  nlohmann::json document = {{"table", table},
                             {"patients", per_patient},
                             {"prepare_seconds", l.prepared->prepare_seconds},
                             {"prepare_anchors_seconds", l.prepared->anchors_seconds}};
  document["real_data"] = real_data_check(out);
  landmark_set_table(out, document);
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  std::ofstream file(std::filesystem::path(out_dir != nullptr ? out_dir : ".") /
                     "scaling.accuracy.json");
  file << document.dump(2) << "\n";
}

// Landmark sets and locality: per bone, the mean surface error for each
// landmark set, over patients of two kinds: the synthetic patients as they
// are (the atlas under one affine map per bone), and the same with local
// shape variation — around every bony landmark its bone's surface (and the
// landmark) displaced by a bump of 50 mm radius and a random 2.5 mm-per-axis
// amplitude, so that e.g. the distal femur widens differently from the shaft.
// Each kind is scaled twice: every landmark on the bone's affine part
// ("one affine": local_radius_mm = 0, the design before local landmarks) and
// with the atlas's local landmarks acting locally ("local").
struct BoneTruth {
  mmm::atlas::Atlas atlas;
  std::map<std::string, mmm::mesh::IndexedMesh> bones;  // full levels
};

BoneTruth make_bone_truth(const Loaded& l, std::uint64_t seed, double height_mm, bool local) {
  mmm::atlas::PatientOptions options;
  options.seed = seed;
  options.height_mm = height_mm;
  const mmm::atlas::PatientDeformation deformation =
      mmm::atlas::make_patient_deformation(l.atlas, options);
  BoneTruth truth;
  truth.atlas = mmm::atlas::deform_atlas(l.atlas, deformation);
  for (const auto& bone : l.atlas.bones) {
    truth.bones[bone.name] =
        mmm::atlas::deform_bone_mesh(deformation, bone.name, l.meshes.at(bone.name).at("full"));
  }
  if (!local) return truth;
  std::mt19937_64 random(seed * 7919U + 13U);
  std::normal_distribution<double> amplitude(0.0, 2.5);
  for (const std::string& name : bony_landmarks()) {
    mmm::atlas::Landmark* landmark = nullptr;
    for (auto& candidate : truth.atlas.landmarks) {
      if (candidate.name == name) landmark = &candidate;
    }
    if (landmark == nullptr) continue;
    const Eigen::Vector3d centre = landmark->position;
    const Eigen::Vector3d delta(amplitude(random), amplitude(random), amplitude(random));
    Eigen::MatrixX3d& V = truth.bones.at(landmark->bone).V;
    for (Eigen::Index i = 0; i < V.rows(); ++i) {
      const double r = (Eigen::Vector3d(V.row(i).transpose()) - centre).norm() / 50.0;
      V.row(i) += scaling::wendland_c2(r) * delta.transpose();
    }
    landmark->position += delta;
  }
  return truth;
}

void landmark_set_table(std::ostream& out, nlohmann::json& document) {
  const Loaded& l = loaded();
  const int patients = std::getenv("MMM_BENCH_PATIENTS") != nullptr
                           ? std::atoi(std::getenv("MMM_BENCH_PATIENTS"))
                           : 10;
  const auto plus = [](std::vector<std::string> names, const std::vector<std::string>& more) {
    names.insert(names.end(), more.begin(), more.end());
    return names;
  };
  const std::vector<std::pair<std::string, std::vector<std::string>>> sets = {
      {"station", kStation},
      {"+ASIS", plus(kStation, {"asis_r", "asis_l"})},
      {"+epicondyles", plus(kStation, {"lateral_epicondyle_r", "medial_epicondyle_r"})},
      {"+malleoli", plus(kStation, {"lateral_malleolus_r", "medial_malleolus_r"})},
      {"+heel", plus(kStation, {"heel_r"})},
      {"+8 bony", plus(kStation, kBony)}};
  // Subset -> superset pairs whose per-bone error must not rise.
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t s = 1; s < sets.size(); ++s) pairs.emplace_back(0, s);
  for (std::size_t s = 1; s + 1 < sets.size(); ++s) pairs.emplace_back(s, sets.size() - 1);
  nlohmann::json tables = nlohmann::json::object();
  // $MMM_BENCH_SET_VARIANTS: which of the four to run (affine/local truth x
  // one affine/local landmarks), e.g. "al,ll"; default all four.
  const std::string variants = std::getenv("MMM_BENCH_SET_VARIANTS") != nullptr
                                   ? std::getenv("MMM_BENCH_SET_VARIANTS")
                                   : "aa,al,la,ll";
  for (const bool local_truth : {false, true}) {
    for (const double radius : {0.0, scaling::AtlasScalingOptions{}.local_radius_mm}) {
      const std::string code = std::string(local_truth ? "l" : "a") + (radius > 0.0 ? "l" : "a");
      if (variants.find(code) == std::string::npos) continue;
      scaling::AtlasScalingOptions options;
      options.local_radius_mm = radius;
      options.muscle.max_penetration_iterations = 0;  // bones only are measured here
      // error[set][patient][bone]
      std::vector<std::vector<std::map<std::string, double>>> error(sets.size());
      for (int p = 0; p < patients; ++p) {
        const std::uint64_t seed = 101 + static_cast<std::uint64_t>(p);
        const double height = 1500.0 + 550.0 * p / std::max(1, patients - 1);
        const BoneTruth truth = make_bone_truth(l, seed, height, local_truth);
        for (std::size_t s = 0; s < sets.size(); ++s) {
          const scaling::ScaledAtlas scaled =
              scaling::scale_atlas(*l.prepared, landmark_set(truth.atlas, sets[s].second), options);
          std::map<std::string, double> per_bone;
          std::vector<double> mean(l.atlas.bones.size());
          mmm::parallel_for(l.atlas.bones.size(), 2, [&](std::size_t b) {
            const std::string& bone = l.atlas.bones[b].name;
            mean[b] =
                mmm::mesh::surface_distance(scaled.meshes.at(bone).at("full"), truth.bones.at(bone))
                    .mean_mm;
          });
          for (std::size_t b = 0; b < mean.size(); ++b) per_bone[l.atlas.bones[b].name] = mean[b];
          error[s].push_back(per_bone);
        }
      }
      const std::string name = std::string(local_truth ? "local variation" : "affine patients") +
                               ", " + (radius > 0.0 ? "local landmarks" : "one affine");
      out << "\nper-bone mean surface distance (mm), " << name << ", median over " << patients
          << " patients:\n"
          << std::left << std::setw(14) << "set";
      for (const auto& bone : l.atlas.bones) out << " " << std::setw(10) << bone.name;
      out << "\n";
      nlohmann::json table;
      for (std::size_t s = 0; s < sets.size(); ++s) {
        out << std::setw(14) << sets[s].first;
        for (const auto& bone : l.atlas.bones) {
          std::vector<double> values;
          for (const auto& patient : error[s]) values.push_back(patient.at(bone.name));
          out << " " << std::setw(10) << fixed(median(values), 2);
          table["median"][sets[s].first][bone.name] = median(values);
        }
        out << "\n";
      }
      // The largest rise of any bone's error, over patients, per pair.
      out << "largest rise of a bone's mean error when landmarks are added (any patient):\n";
      for (const auto& [sub, super] : pairs) {
        double rise = -1e9;
        std::string where;
        for (int p = 0; p < patients; ++p) {
          for (const auto& bone : l.atlas.bones) {
            const double d = error[super][static_cast<std::size_t>(p)].at(bone.name) -
                             error[sub][static_cast<std::size_t>(p)].at(bone.name);
            if (d > rise) {
              rise = d;
              where = bone.name + " (seed " + std::to_string(101 + p) + ")";
            }
          }
        }
        out << "  " << sets[sub].first << " -> " << sets[super].first << ": " << fixed(rise, 3)
            << " mm, " << where << (rise > 0.2 ? "  ABOVE 0.2 mm" : "") << "\n";
        table["largest_rise_mm"][sets[sub].first + " -> " + sets[super].first] = {{"rise_mm", rise},
                                                                                  {"where", where}};
      }
      tables[name] = table;
      std::cerr << name << " done\n";
      out.flush();
    }
  }
  document["landmark_sets"] = tables;
}

// The table on stdout and beside the JSON (scaling.accuracy.txt), which
// bench/table.py prints above the speed table.
void write_accuracy_table() {
  std::ostringstream text;
  accuracy_table(text);
  std::cout << text.str();
  const char* out_dir = std::getenv("MMM_BENCH_OUT_DIR");
  std::ofstream file(std::filesystem::path(out_dir != nullptr ? out_dir : ".") /
                     "scaling.accuracy.txt");
  file << text.str();
}

void BM_PrepareAtlas(benchmark::State& state) {
  const Loaded& l = loaded();
  for (auto _ : state) {
    benchmark::DoNotOptimize(scaling::prepare_atlas(l.atlas, l.meshes));
  }
}
BENCHMARK(BM_PrepareAtlas)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_ScaleWholeAtlas(benchmark::State& state) {
  const Loaded& l = loaded();
  const Truth truth = make_truth(l, 7, 1780.0);
  const LandmarkSet set = landmark_set(truth.atlas, kStation);
  for (auto _ : state) {
    benchmark::DoNotOptimize(scaling::scale_atlas(*l.prepared, set));
  }
}
BENCHMARK(BM_ScaleWholeAtlas)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_ScaleWholeAtlasBony(benchmark::State& state) {
  const Loaded& l = loaded();
  const Truth truth = make_truth(l, 7, 1780.0);
  std::vector<std::string> names = kStation;
  names.insert(names.end(), kBony.begin(), kBony.end());
  const LandmarkSet set = landmark_set(truth.atlas, names);
  for (auto _ : state) {
    benchmark::DoNotOptimize(scaling::scale_atlas(*l.prepared, set));
  }
}
BENCHMARK(BM_ScaleWholeAtlasBony)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

int main(int argc, char** argv) {
  return mmm::bench::run_suite(argc, argv, "mmm_bench_scaling", write_accuracy_table);
}

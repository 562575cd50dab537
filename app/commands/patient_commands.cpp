// mmm patient synth: synthetic patients (ground truth + biplanar radiographs).
// mmm patient clicks: a scripted operator's landmark clicks on them (demos
// and tests only).

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "app/commands/commands.h"
#include "core/atlas/bone_set.h"
#include "core/atlas/bone_set_patient.h"
#include "core/atlas/foreign_bones.h"
#include "core/atlas/synthetic_patient.h"
#include "core/errors.h"
#include "core/landmarks/scripted_clicks.h"

namespace mmm::app {
namespace {

struct SynthArgs {
  std::string atlas;
  std::string out;
  std::uint64_t seed = 1;
  std::optional<double> height_mm;
  double pixel_pitch_mm = 0.5;
  bool local_shape = false;
  bool muscles_in_air = false;
  bool pinhole = false;
  bool dicom = false;
  bool json = false;
};

constexpr const char* kMusclesInAirHelp =
    "Render the muscles as soft tissue standing in air, bone on top, rather than the limb filled "
    "with soft tissue that the bones replace (the default, as in a real radiograph)";
constexpr const char* kDicomHelp =
    "Also write each radiograph as a DICOM file (radiographs/<view>.dcm: DX with its geometry "
    "attributes and an invented patient identity, which a study removes)";
constexpr const char* kPinholeHelp =
    "Render two conventional (pinhole) radiographs rather than an EOS-type slot scan, conic "
    "across the leg and parallel along it (the default)";

image::ProjectionModel projection_model(bool pinhole) {
  return pinhole ? image::ProjectionModel::kPinhole : image::ProjectionModel::kSlotScanning;
}

void run_synth(const SynthArgs& args) {
  atlas::SyntheticPatientOptions options;
  options.deformation.seed = args.seed;
  options.deformation.height_mm = args.height_mm;
  options.detector_pixel_pitch_mm = args.pixel_pitch_mm;
  options.deformation.local_shape = args.local_shape;
  options.soft_tissue_envelope = !args.muscles_in_air;
  options.model = projection_model(args.pinhole);
  options.write_dicom = args.dicom;
  const atlas::SyntheticPatientReport report =
      atlas::make_synthetic_patient(args.atlas, args.out, options);
  if (args.json) {
    const nlohmann::json json = {{"seed", report.factors.seed},
                                 {"height_mm", report.factors.height_mm},
                                 {"stature_scale", report.factors.stature_scale},
                                 {"pelvis_width", report.factors.pelvis_width},
                                 {"neck_angle_deg", report.factors.neck_angle_deg},
                                 {"segment_length", report.factors.length},
                                 {"segment_width", report.factors.width},
                                 {"image_size", {report.frontal_width, report.frontal_height}},
                                 {"pixel_spacing_mm", report.pixel_spacing_mm},
                                 {"seconds", report.seconds}};
    std::cout << json.dump(2) << '\n';
    return;
  }
  std::cout << std::fixed << std::setprecision(3) << "synthetic patient, seed "
            << report.factors.seed << ": stature " << std::setprecision(0)
            << report.factors.height_mm << " mm (scale " << std::setprecision(3)
            << report.factors.stature_scale << "), pelvis width x" << report.factors.pelvis_width
            << ", femoral neck-shaft angle " << std::showpos << std::setprecision(1)
            << report.factors.neck_angle_deg << std::noshowpos << " deg\n"
            << std::setprecision(3);
  for (const auto& [bone, factor] : report.factors.length) {
    std::cout << "  " << std::left << std::setw(12) << bone << " length x" << factor << "  width x"
              << report.factors.width.at(bone) << '\n';
  }
  std::cout << "radiographs " << report.frontal_width << " x " << report.frontal_height << " px, "
            << report.pixel_spacing_mm << " mm/px at the isocentre; written to " << args.out
            << " in " << std::setprecision(1) << report.seconds << " s\n"
            << "  " << args.out << "/atlas (ground truth), ground_truth.json, radiographs/"
            << "{frontal,lateral}.png + views.json\n";
}

struct BonesArgs {
  std::string manifest;  // from-bones
  std::string data;      // foreign
  std::string atlas;
  std::string out;
  std::uint64_t seed = 1;
  std::optional<double> height_mm;
  double pixel_pitch_mm = 0.5;
  bool local_shape = false;
  bool muscles_in_air = false;
  bool pinhole = false;
  bool dicom = false;
};

void print_bone_patient(const atlas::BoneSetPatientReport& report, const std::string& out) {
  std::cout << std::fixed << std::setprecision(1) << "patient of " << report.bones
            << " bones: " << report.landmarks_given << " landmarks given, "
            << report.landmarks_derived << " derived from the atlas; radiographs "
            << report.frontal_width << " x " << report.frontal_height << " px, "
            << std::setprecision(3) << report.pixel_spacing_mm
            << " mm/px at the isocentre; written to " << out << " in " << std::setprecision(1)
            << report.seconds << " s\n"
            << "  " << out << "/bones (ground truth), ground_truth.json, radiographs/"
            << "{frontal,lateral}.png + views.json\n";
  for (const std::string& bone : report.solidified) {
    std::cout << "  " << bone
              << ": not a single closed surface; the truth and the radiographs use the boundary "
                 "of the solid it encloses ("
              << atlas::kSolidifyGridMm << " mm grid)\n";
  }
}

atlas::PatientRadiographOptions radiograph_options(const BonesArgs& args) {
  atlas::PatientRadiographOptions options;
  options.detector_pixel_pitch_mm = args.pixel_pitch_mm;
  options.seed = args.seed;
  options.soft_tissue_envelope = !args.muscles_in_air;
  options.model = projection_model(args.pinhole);
  options.write_dicom = args.dicom;
  return options;
}

void run_from_bones(const BonesArgs& args) {
  const atlas::BoneSet set = atlas::read_bone_set(args.manifest);
  print_bone_patient(
      atlas::make_bone_set_patient(set, args.atlas, args.out, radiograph_options(args)), args.out);
}

void run_foreign(const BonesArgs& args) {
  atlas::ForeignBoneOptions options;
  options.deformation.seed = args.seed;
  options.deformation.height_mm = args.height_mm;
  options.deformation.local_shape = args.local_shape;
  const atlas::BoneSet set = atlas::gait2392_bone_set(args.atlas, args.data, options);
  const atlas::BoneSetPatientReport report =
      atlas::make_bone_set_patient(set, args.atlas, args.out, radiograph_options(args));
  atlas::write_bone_set(set, std::filesystem::path(args.out) / "bone_set");
  print_bone_patient(report, args.out);
  std::cout << "  " << args.out << "/bone_set/manifest.yaml: the bones as a bone set\n";
}

struct ClickArgs {
  std::string patient;
  std::string out;
  landmarks::ScriptedClickOptions options;
};

void run_clicks(const ClickArgs& args) {
  const std::filesystem::path truth_file =
      std::filesystem::path(args.patient) / "ground_truth.json";
  std::ifstream in(truth_file);
  if (!in) {
    throw InvalidInputError(truth_file.string() +
                            ": cannot be read; give the folder that mmm patient synth wrote");
  }
  nlohmann::json truth;
  try {
    truth = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& error) {
    throw InvalidInputError(truth_file.string() + ": not JSON (" + error.what() + ")");
  }
  const nlohmann::json clicks = landmarks::scripted_clicks(truth, args.options);
  std::ofstream out(args.out);
  out << clicks.dump(2) << '\n';
  if (!out) {
    throw InvalidInputError(args.out + ": cannot be written");
  }
  std::cerr << "scripted operator (not a person): " << args.options.landmarks.size()
            << " landmarks from " << truth_file.string() << " + Gaussian click noise of "
            << args.options.noise_px << " px (seed " << args.options.seed << ") -> " << args.out
            << '\n';
}

}  // namespace

void register_patient_commands(CLI::App& app) {
  auto* patient = app.add_subcommand("patient", "Synthetic patients for tests and demos");
  patient->require_subcommand(1);
  auto args = std::make_shared<SynthArgs>();
  auto* synth = patient->add_subcommand(
      "synth",
      "Deform an atlas by a known plausible map (the ground truth) and render its "
      "calibrated frontal and lateral radiographs");
  synth->add_option("--atlas", args->atlas, "Atlas folder")->required();
  synth->add_option("-o,--out", args->out, "Patient folder to write")->required();
  synth->add_option("--seed", args->seed, "Random seed of the deformation and noise");
  synth->add_option("--height-mm", args->height_mm, "Stature (mm), 1000-2300")
      ->check(CLI::Range(1000.0, 2300.0));
  synth
      ->add_option("--pixel-pitch", args->pixel_pitch_mm,
                   "Detector pixel pitch (mm); 0.5 gives 0.38 mm at the isocentre")
      ->check(CLI::Range(0.05, 2.0));
  synth->add_flag("--local-shape", args->local_shape,
                  "Add local shape to the long bones (torsion, bowing, bumps): what no smooth "
                  "map of the atlas produces");
  synth->add_flag("--muscles-in-air", args->muscles_in_air, kMusclesInAirHelp);
  synth->add_flag("--pinhole", args->pinhole, kPinholeHelp);
  synth->add_flag("--dicom", args->dicom, kDicomHelp);
  synth->add_flag("--json", args->json, "Print the drawn factors as JSON");
  synth->callback([args] { run_synth(*args); });

  auto bones = std::make_shared<BonesArgs>();
  auto* from_bones = patient->add_subcommand(
      "from-bones",
      "Make a patient folder (calibrated radiograph pair + ground truth) from any bone "
      "surfaces (CT segmentations, another model) listed in a bone-set manifest");
  from_bones->add_option("manifest", bones->manifest, "Bone-set manifest (YAML)")->required();
  from_bones->add_option("--atlas", bones->atlas, "Atlas whose bone and landmark names apply")
      ->required();
  from_bones->add_option("-o,--out", bones->out, "Patient folder to write")->required();
  from_bones->add_option("--seed", bones->seed, "Random seed of the detector noise");
  from_bones
      ->add_option("--pixel-pitch", bones->pixel_pitch_mm,
                   "Detector pixel pitch (mm); 0.5 gives 0.38 mm at the isocentre")
      ->check(CLI::Range(0.05, 2.0));
  from_bones->add_flag("--muscles-in-air", bones->muscles_in_air, kMusclesInAirHelp);
  from_bones->add_flag("--pinhole", bones->pinhole, kPinholeHelp);
  from_bones->add_flag("--dicom", bones->dicom, kDicomHelp);
  from_bones->callback([bones] { run_from_bones(*bones); });

  auto foreign = std::make_shared<BonesArgs>();
  auto* foreign_command = patient->add_subcommand(
      "foreign",
      "A patient with another person's bones: gait2392's bone geometry placed on the atlas, "
      "given a synthetic patient's proportions (and local shape), rendered like from-bones");
  foreign_command->add_option("--atlas", foreign->atlas, "Atlas folder")->required();
  foreign_command->add_option("--data", foreign->data, "The shared data folder (gait2392/)")
      ->required();
  foreign_command->add_option("-o,--out", foreign->out, "Patient folder to write")->required();
  foreign_command->add_option("--seed", foreign->seed, "Random seed of the proportions and noise");
  foreign_command->add_option("--height-mm", foreign->height_mm, "Stature (mm), 1000-2300")
      ->check(CLI::Range(1000.0, 2300.0));
  foreign_command->add_flag("--local-shape", foreign->local_shape,
                            "Add local shape to the long bones (torsion, bowing, bumps)");
  foreign_command->add_option("--pixel-pitch", foreign->pixel_pitch_mm, "Detector pixel pitch (mm)")
      ->check(CLI::Range(0.05, 2.0));
  foreign_command->add_flag("--muscles-in-air", foreign->muscles_in_air, kMusclesInAirHelp);
  foreign_command->add_flag("--pinhole", foreign->pinhole, kPinholeHelp);
  foreign_command->add_flag("--dicom", foreign->dicom, kDicomHelp);
  foreign_command->callback([foreign] { run_foreign(*foreign); });

  auto clicks = std::make_shared<ClickArgs>();
  auto* click = patient->add_subcommand(
      "clicks",
      "A scripted operator, for demos and tests only: landmark clicks from a synthetic "
      "patient's ground truth with Gaussian noise, as a submission for 'mmm task submit --file'");
  click->add_option("patient", clicks->patient, "Patient folder (from mmm patient synth)")
      ->required();
  click->add_option("-o,--out", clicks->out, "Submission JSON to write")->required();
  click
      ->add_option("--noise-px", clicks->options.noise_px,
                   "Standard deviation of each click coordinate (pixels)")
      ->check(CLI::Range(0.0, 50.0));
  click->add_option("--seed", clicks->options.seed, "Random seed of the noise");
  click
      ->add_option("--landmarks", clicks->options.landmarks,
                   "Landmarks to click (default: femoral head, patella and ankle centres)")
      ->delimiter(',');
  click->callback([clicks] { run_clicks(*clicks); });
}

}  // namespace mmm::app

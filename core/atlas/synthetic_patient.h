#pragma once
// A synthetic patient: the atlas deformed by a known, anatomically plausible
// non-uniform map (patient_deformation.h) — the ground truth every accuracy
// test compares against — and the calibrated biplanar radiograph pair
// (EOS-like) an operator would read landmarks from.
//
// Folder written (`mmm patient synth ... -o PDIR`):
//   atlas/                  the patient's own atlas (atlas.yaml + meshes): ground truth
//   ground_truth.json       seed, stature, factors, every landmark (mm) and its pixel
//                           position in each view
//   radiographs/frontal.png, lateral.png
//                           16-bit digitally reconstructed radiographs (drr.h): bones
//                           at mu_bone, muscles at mu_soft, detector noise
//   radiographs/views.json  the calibration sidecar (projection.h: 3x4 matrices,
//                           pixel spacing, source)
//   radiographs/*_preview.png  8-bit, windowed, for people to look at;
//                           pair_preview.png both side by side at half size

#include <filesystem>
#include <string>

#include "core/atlas/patient_deformation.h"
#include "core/image/drr.h"
#include "core/image/projection.h"

namespace mmm::atlas {

struct SyntheticPatientOptions {
  PatientOptions deformation;
  // Detector geometry; the isocentre and field of view are set from the
  // patient's bones (their bounding box plus `field_margin_mm`).
  double source_to_isocentre_mm = 1300.0;
  double source_to_detector_mm = 1700.0;
  double detector_pixel_pitch_mm = 0.5;  // 0.38 mm at the isocentre
  double field_margin_mm = 40.0;
  double mu_bone_per_mm = image::kBoneMuPerMm;
  double mu_soft_per_mm = image::kSoftTissueMuPerMm;
  std::string muscle_level = "lod1";  // muscles enter the DRR at this resolution
  bool soft_tissue_envelope = true;   // the limb filled (patient_radiographs.h)
  // Slot-scanning (EOS-type) views, or a conventional pinhole pair.
  image::ProjectionModel model = image::ProjectionModel::kSlotScanning;
  bool write_dicom = false;             // also <view>.dcm (patient_radiographs.h)
  image::RadiographOptions radiograph;  // seed: the patient's seed unless set otherwise
  int threads = 2;
};

struct SyntheticPatientReport {
  PatientFactors factors;
  double seconds = 0.0;
  int frontal_width = 0;
  int frontal_height = 0;
  double pixel_spacing_mm = 0.0;
};

// Reads the atlas in `atlas_dir`, deforms it, renders the radiographs and
// writes the folder `out_dir` (replaced only once complete). Throws IoError
// for an unreadable atlas and InvalidInputError for options out of range.
SyntheticPatientReport make_synthetic_patient(const std::filesystem::path& atlas_dir,
                                              const std::filesystem::path& out_dir,
                                              const SyntheticPatientOptions& options);

}  // namespace mmm::atlas

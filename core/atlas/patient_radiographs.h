#pragma once
// The calibrated biplanar radiograph pair of a patient made of surfaces (a
// synthetic patient, or bones from any source): frontal and lateral
// digitally reconstructed radiographs (drr.h) centred on the bones, written
// with their view sidecar and 8-bit previews.
//
// Folder written (`dir`):
//   frontal.png, lateral.png      16-bit radiographs: bones at mu_bone, soft
//                                 tissue at mu_soft, detector noise
//   views.json                    the calibration sidecar (projection.h)
//   *_preview.png, pair_preview.png  8-bit windowed pictures for people
//
// The isocentre is the centre of the bones' bounding box and the field covers
// the box with `field_margin_mm` on every side.

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "core/image/drr.h"
#include "core/image/projection.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

struct PatientRadiographOptions {
  double source_to_isocentre_mm = 1300.0;
  double source_to_detector_mm = 1700.0;
  double detector_pixel_pitch_mm = 0.5;  // 0.38 mm at the isocentre
  double field_margin_mm = 40.0;
  // Slot-scanning views (an EOS-type scan: conic across, parallel along the
  // leg) or pinhole views (two conventional radiographs).
  image::ProjectionModel model = image::ProjectionModel::kSlotScanning;
  // Also write each view as a DICOM file (<view>.dcm: DX, the system's
  // geometry attributes, an invented identity to be removed by a study).
  bool write_dicom = false;
  double mu_bone_per_mm = image::kBoneMuPerMm;
  double mu_soft_per_mm = image::kSoftTissueMuPerMm;
  // Soft tissue as in a real limb: an envelope around bones and muscles
  // (limb_envelope.h) filled with tissue at mu_soft, the bones replacing it
  // (mu_bone - mu_soft), the muscles only muscle_contrast_per_mm above it
  // (muscle against fat: 0.021 against 0.018 /mm). Off: the soft-tissue
  // surfaces at mu_soft in air and the bones at mu_bone on top (sharp muscle
  // edges as bright as millimetres of bone: no real radiograph looks so).
  bool soft_tissue_envelope = true;
  double muscle_contrast_per_mm = 0.003;
  double envelope_fat_mm = 8.0;
  image::RadiographOptions radiograph;  // detector noise; its seed is combined with `seed`
  std::uint64_t seed = 1;               // the patient's seed
  int threads = 2;
};

// Throws InvalidInputError for options out of range (pitch <= 0, negative
// margin or attenuation) or no bones, IoError when a file cannot be written.
std::array<image::RadiographView, 2> write_patient_radiographs(
    const std::map<std::string, mesh::IndexedMesh>& bones,
    const std::map<std::string, mesh::IndexedMesh>& soft_tissue, const std::filesystem::path& dir,
    const PatientRadiographOptions& options);

}  // namespace mmm::atlas

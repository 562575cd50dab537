#pragma once
// The de-identified form of a DICOM radiograph (dicom_radiograph.h): what a
// study stores instead of the DICOM file.
//
// The PS3.15 Annex E Basic Application Level Confidentiality Profile removes
// or replaces every attribute that could identify the patient (name, ID,
// birth date, ...), the study (dates, times, accession number, UIDs), the
// institution, the physicians and operators, and the device (serial number).
// Here that holds by construction: only the attributes of DicomRadiograph are
// written, and none of them identifies anyone. The SOP Instance UID is kept
// only as its SHA-256, so that the same image loaded twice is recognised
// without the UID being stored.
//
// One JSON document:
//   {"format": "mmm-deidentified-radiograph", "version": 1,
//    "modality": "DX", "sop_class_uid": "...", "transfer_syntax_uid": "...",
//    "photometric_interpretation": "MONOCHROME2", "bits_stored": 16,
//    "pixel_signed": false, "rows": 48, "columns": 64,
//    "rescale_slope": 1, "rescale_intercept": 0,
//    "sop_instance_uid_sha256": "<64 hex>",
//    "value_map": {"value_min": 0, "scale": 1, "inverted": false},
//    "window": {"centre": 30000, "width": 40000, "source": "file"},
//    and when known: "imager_pixel_spacing_mm": [row, column],
//      "pixel_spacing_mm": [row, column], "magnification_factor",
//      "distance_source_to_detector_mm", "distance_source_to_patient_mm",
//      "view_position", "patient_orientation": ["L", "F"],
//      "image_laterality", "pixel_spacing_calibration_type",
//    "png_base64": "<16-bit grayscale PNG of the image>",
//    "sha256": "<hex SHA-256 of the PNG bytes>"}
// Numbers are written with enough digits to read back exactly.

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/image/dicom_radiograph.h"

namespace mmm::image {

// The largest de-identified text accepted: base64 of the largest PNG
// (kPngMaxFileBytes, 256 MiB -> 342 MiB) plus the attributes.
inline constexpr std::size_t kDeidentifiedRadiographMaxBytes = std::size_t{384} << 20U;

// The JSON text above. Throws InvalidInputError when the image is empty or
// its size is not columns x rows.
std::string deidentified_radiograph_text(const DicomRadiograph& radiograph);

// Parses and checks a de-identified radiograph (bounded_json.h, at most
// kDeidentifiedRadiographMaxBytes). Throws IoError naming `source` and the
// field: not JSON, wrong format or version, an unknown or missing field, a
// value of the wrong type or out of range (the checks of reading DICOM), an
// image whose SHA-256 does not match, that is not a 16-bit grayscale PNG, or
// whose size is not columns x rows.
DicomRadiograph deidentified_radiograph_from_text(std::string_view text,
                                                  const std::filesystem::path& source);

}  // namespace mmm::image

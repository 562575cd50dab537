#pragma once
// A radiograph written as a DICOM file (DX for presentation, MONOCHROME2,
// 16 bits, explicit VR little endian) through GDCM, with the geometry
// attributes that dicom_views.h reads back: what the synthetic patients give
// a study that takes DICOM, and what tests use as another writer's files.
// The identity attributes are the caller's (a synthetic patient's invented
// name and dates, so that de-identification has something to remove).

#include <array>
#include <string>

#include "core/image/image.h"

namespace mmm::image {

struct DicomExport {
  std::string view_position;                       // (0018,5101) "AP", "LL", ...
  std::array<std::string, 2> patient_orientation;  // (0020,0020) e.g. {"L", "F"}
  double row_pitch_mm = 0.3;                       // (0018,1164) at the detector
  double column_pitch_mm = 0.3;
  double source_to_detector_mm = 1700.0;  // (0018,1110)
  double source_to_patient_mm = 1300.0;   // (0018,1111)
  double window_centre = 32768.0;         // (0028,1050)
  double window_width = 65536.0;          // (0028,1051)
  // Identity and instance: written as given.
  std::string patient_name;        // (0010,0010)
  std::string patient_id;          // (0010,0020)
  std::string patient_birth_date;  // (0010,0030) YYYYMMDD
  std::string study_date;          // (0008,0020) YYYYMMDD
  std::string sop_instance_uid;    // (0008,0018)
};

// The DICOM file's bytes. Throws InvalidInputError for an empty image, a
// non-positive pitch or distance, or a UID that is not digits and dots
// (at most 64 characters); SolverError-free: IoError when GDCM fails.
std::string dicom_radiograph_bytes(const GrayImage16& image, const DicomExport& options);

}  // namespace mmm::image

#pragma once
// Reading a projection radiograph (DX, CR or secondary capture) from a DICOM
// file (PS3.10) through GDCM, into a 16-bit image for display plus the few
// attributes that describe its geometry. Nothing that identifies the patient,
// the study or the institution is kept: the struct below has no field for it.
//
//   bytes -> size limit, "DICM" check -> structure walk (dicom_structure.h:
//     GDCM aborts on truncated files) -> GDCM parses the data set (in memory)
//     -> attributes checked (SOP class, one sample, MONOCHROME1/2, 8..16 bits
//        stored, rows/columns, one frame, strict DS values)
//     -> pixels decoded by GDCM (native, RLE, JPEG, JPEG-LS, JPEG 2000)
//     -> stored values masked to Bits Stored, sign-extended when signed
//     -> modality values: value = stored * slope + intercept (0028,1053/1052)
//     -> linear map of [value_min, value_max] onto 0..65535, inverted for
//        MONOCHROME1 so that brighter always means more attenuation
//     -> window: Window Center/Width (0028,1050/1051, first value) or the
//        0.5 / 99.5 percentiles of the image, in the 16-bit units.
//
// Not applied: VOI LUT Sequence (0028,3010) (a file with one and no window
// values gets the percentile window) and VOI LUT Function (a SIGMOID window is
// shown linearly). A Modality LUT Sequence (0028,3000) is refused: its output,
// not the stored values, is what the window refers to.

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "core/image/image.h"

namespace mmm::image {

// A file above this size is refused before it is parsed (a 4,000 x 4,000
// 16-bit radiograph is 32 MiB uncompressed).
inline constexpr std::uintmax_t kDicomMaxFileBytes = std::uintmax_t{512} << 20U;
// Rows and Columns above this are refused before any pixel is decoded (an
// EOS full-body image is about 2,000 x 9,000).
inline constexpr int kDicomMaxSide = 20'000;
// The longest a trial decoding (in a child process, see read_dicom_radiograph)
// may take: a 512 MiB JPEG 2000 image decodes in well under a minute.
inline constexpr std::chrono::seconds kDicomDecodeTimeLimit{120};

// Where the display window comes from.
enum class DicomWindowSource {
  kFile,         // Window Center / Width (0028,1050 / 0028,1051), first value
  kPercentiles,  // none in the file: the image's 0.5 and 99.5 percentiles
};

// A linear display window in the units of DicomRadiograph::image (0..65535):
// samples at or below centre - width / 2 are black, at or above centre +
// width / 2 white. DICOM's own definition (PS3.3 C.11.2.1.2.1) shifts both
// ends by half a unit; that is below one 16-bit step and ignored.
struct DicomWindow {
  double centre = 32767.5;
  double width = 65535.0;
  DicomWindowSource source = DicomWindowSource::kPercentiles;
  friend bool operator==(const DicomWindow&, const DicomWindow&) = default;
};

// How the modality values (after rescale) were mapped onto the 16-bit image:
//   s        = (value - value_min) * scale        in [0, 65535]
//   stored16 = round(s)            (MONOCHROME2)
//   stored16 = 65535 - round(s)    (MONOCHROME1, inverted)
// so value = (inverted ? 65535 - stored16 : stored16) / scale + value_min.
// scale = 65535 / (value_max - value_min), or 1 for a constant image. When
// the values span at most 65535 integer steps (8 to 16 bits stored, slope 1)
// the map is exact: every stored value gets its own 16-bit sample.
struct DicomValueMap {
  double value_min = 0.0;
  double scale = 1.0;
  bool inverted = false;
  friend bool operator==(const DicomValueMap&, const DicomValueMap&) = default;
};

// Row spacing then column spacing (mm), the order of DICOM's Pixel Spacing:
// [0] between the centres of adjacent rows (vertical), [1] between adjacent
// columns (horizontal). PS3.3 10.7.1.3.
using PixelSpacingMm = std::array<double, 2>;

// A radiograph read from DICOM, de-identified by construction: only these
// fields are kept.
struct DicomRadiograph {
  GrayImage16 image;  // columns x rows, brighter = more attenuation
  DicomValueMap value_map;
  DicomWindow window;

  // Kept attributes (strings trimmed of DICOM's space / NUL padding).
  std::string modality;                    // (0008,0060) "DX", "CR", "OT", ...
  std::string sop_class_uid;               // (0008,0016)
  std::string transfer_syntax_uid;         // (0002,0010) of the file
  std::string photometric_interpretation;  // (0028,0004) MONOCHROME1 or MONOCHROME2
  int bits_stored = 16;                    // (0028,0101) 8..16
  bool pixel_signed = false;               // (0028,0103) == 1
  int rows = 0;                            // (0028,0010) == image.height
  int columns = 0;                         // (0028,0011) == image.width
  double rescale_slope = 1.0;              // (0028,1053), 1 when absent
  double rescale_intercept = 0.0;          // (0028,1052), 0 when absent
  // SHA-256 (64 lowercase hex) of the SOP Instance UID (0008,0018): tells two
  // copies of one image apart from two images without keeping the UID.
  std::string sop_instance_uid_sha256;

  // Geometry (absent when the file has no value; a value present must parse).
  std::optional<PixelSpacingMm> imager_pixel_spacing;  // (0018,1164), detector plane
  std::optional<PixelSpacingMm> pixel_spacing;         // (0028,0030), see radiograph_spacing
  std::optional<double> magnification_factor;  // (0018,1114) Estimated Radiographic Magnification
  std::optional<double> distance_source_to_detector_mm;  // (0018,1110) SID
  std::optional<double> distance_source_to_patient_mm;   // (0018,1111) SOD, to the isocentre
  std::optional<std::string> view_position;              // (0018,5101) "AP", "PA", "LL", ...
  // (0020,0020): the patient direction of the rows (towards increasing
  // column index) then of the columns (increasing row index), each a string
  // of A/P/R/L/H/F, e.g. {"L", "F"} for an AP view.
  std::optional<std::array<std::string, 2>> patient_orientation;
  std::optional<std::string> image_laterality;                // (0020,0062) R, L, U or B
  std::optional<std::string> pixel_spacing_calibration_type;  // (0028,0A02) GEOMETRY, FIDUCIAL

  friend bool operator==(const DicomRadiograph&, const DicomRadiograph&) = default;
};

// True when the bytes look like a DICOM file: "DICM" at offset 128 (PS3.10
// preamble), or, for a bare data set without preamble (implicit VR little
// endian, as old modalities write), a first element of group 0x0002 or 0x0008
// little endian.
bool looks_like_dicom(std::string_view bytes);

// Reads a radiograph from a DICOM file's bytes; `source` names the file in
// messages. The bytes are decoded first in a child process
// (core/process/isolated_run.h): a file that makes GDCM or a codec abort or
// crash is refused here, the calling process unharmed. Throws IoError naming `source` and the
// attribute at fault, with a hint: above kDicomMaxFileBytes; not DICOM; truncated; an unknown
// transfer syntax or one GDCM cannot decode (the UID named); no Pixel Data (7FE0,0010); a SOP class
// other than CR, DX or secondary capture; Samples per Pixel != 1 or a colour Photometric
// Interpretation; Bits Allocated other than 8 / 16 or Bits Stored outside 8..16; Rows or Columns
// zero or above kDicomMaxSide; more than one frame; a non-numeric or non-finite DS value; a
// spacing, distance or magnification that is not > 0; a Rescale Slope of 0; a
// Window Width < 1; a Patient Orientation or Image Laterality that is not
// one of the defined codes; a Modality LUT Sequence.
DicomRadiograph read_dicom_radiograph(std::string_view bytes, const std::filesystem::path& source);

// The same from a file: its size is checked (stat) before it is read.
DicomRadiograph read_dicom_radiograph(const std::filesystem::path& path);

// Which plane the spacing of a radiograph refers to (PS3.3 10.7.1.3 and the
// DX Detector module, C.8.11.4 / C.8.11.7):
// - Imager Pixel Spacing (0018,1164) is always at the detector's front plane.
// - Pixel Spacing (0028,0030) in a projection radiograph is either equal to
//   Imager Pixel Spacing (the detector plane, not calibrated), or calibrated to
//   the patient (different from it, and/or Pixel Spacing Calibration Type
//   present: GEOMETRY from the magnification, FIDUCIAL from an object of
//   known size).
// - Without Imager Pixel Spacing and calibration type (secondary capture,
//   old CR) the plane of Pixel Spacing cannot be told.
enum class SpacingMeaning {
  kNone,                 // no spacing attribute at all
  kDetector,             // Imager Pixel Spacing, Pixel Spacing absent or equal
  kCalibratedToPatient,  // Pixel Spacing calibrated to the patient plane
  kUnknownPlane,         // Pixel Spacing alone: detector or patient, unknown
};

struct RadiographSpacing {
  SpacingMeaning meaning = SpacingMeaning::kNone;
  // At the detector's front plane: Imager Pixel Spacing, or the calibrated
  // Pixel Spacing times the magnification when only that is known.
  std::optional<PixelSpacingMm> detector_mm;
  // At the isocentre / patient plane: the calibrated Pixel Spacing, or the
  // detector spacing divided by the magnification.
  std::optional<PixelSpacingMm> patient_mm;
  // Detector size / patient size: Estimated Radiographic Magnification
  // Factor, else SID / SOD, else (calibrated case) Imager Pixel Spacing /
  // Pixel Spacing.
  std::optional<double> magnification;
  // One or two sentences for the operator: which attribute, and why.
  std::string explanation;
};

// Pixel Spacing and Imager Pixel Spacing count as equal within a relative
// 1e-4 (DS values are decimal strings of up to 16 characters, often written
// with fewer digits than the other).
RadiographSpacing radiograph_spacing(const DicomRadiograph& radiograph);

}  // namespace mmm::image

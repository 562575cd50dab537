#pragma once
// A radiograph given as a folder of DICOM files (a series, or a whole exam
// exported from a PACS with the frontal and the lateral series in it), and
// the choice of one view's image in it.
//
// A folder is read with bounds checked before anything is read in full: at
// most kDicomFolderMaxDepth levels of sub-folders, kDicomFolderMaxEntries
// entries looked at, kDicomFolderMaxImages images. Files that are not DICOM
// (a README, a viewer's index) are passed over, as is a DICOMDIR; a DICOM
// file that cannot be read as a radiograph is an error naming it. The same
// image found twice (equal SOP Instance UID) counts once. Images come in
// the order of their paths, so a folder reads the same on every machine.
//
// What a study stores for such a folder is its de-identified form: each
// image's de-identified radiograph (deidentified_radiograph.h), and nothing
// of the folder's file names (an export often names folders after the
// patient). One JSON document:
//   {"format": "mmm-deidentified-radiograph-series", "version": 1,
//    "images": [<de-identified radiograph>, ...]}

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/image/dicom_radiograph.h"

namespace mmm::image {

inline constexpr int kDicomFolderMaxDepth = 4;
inline constexpr std::size_t kDicomFolderMaxEntries = 4096;
inline constexpr std::size_t kDicomFolderMaxImages = 32;
// The de-identified series of the largest folder a study takes (1 GiB of
// DICOM) with base64 overhead.
inline constexpr std::size_t kDeidentifiedSeriesMaxBytes = std::size_t{1536} << 20U;

// True when a DICOM file is found in `folder` within the bounds above (only
// the first bytes of files are read). False for a folder that does not
// exist or holds no DICOM file.
bool folder_holds_dicom(const std::filesystem::path& folder);

// Every radiograph in `folder`. Throws IoError naming the folder (or the
// file) with a hint: not a folder; deeper, more entries or more images
// than the bounds; a link to a folder; no DICOM file; a DICOM file that
// read_dicom_radiograph refuses.
std::vector<DicomRadiograph> read_dicom_folder(const std::filesystem::path& folder);

// The de-identified series document above. Throws InvalidInputError for no
// images.
std::string deidentified_series_text(const std::vector<DicomRadiograph>& images);

// True when `bytes` start as the document above (what a study stored for
// a folder).
bool is_deidentified_series(std::string_view bytes);

// Parses and checks the document (each image as deidentified_radiograph_
// from_text does). Throws IoError naming `source` and the field.
std::vector<DicomRadiograph> deidentified_series_from_text(std::string_view text,
                                                           const std::filesystem::path& source);

// The image of `images` for the view `view_name` ("frontal" or "lateral"):
// the only image, or else the only one whose View Position (0018,5101) is a
// frontal (AP, PA) or a lateral (LL, RL, LATERAL) projection. Throws IoError
// naming `source`, listing every image with its View Position, when none or
// several match, or for an unknown view name.
struct SeriesChoice {
  std::size_t index = 0;  // into images
  std::string reason;     // for the log: which image and why
};
SeriesChoice choose_view_image(const std::vector<DicomRadiograph>& images,
                               std::string_view view_name, const std::filesystem::path& source);

}  // namespace mmm::image

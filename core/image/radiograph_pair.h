#pragma once
// A calibrated radiograph pair as one value: the views (projection.h) and the
// PNG bytes of each view's image, so that a study keeps exactly what the
// operator was shown. Serialised (the RadiographPair artifact of a workflow)
// as one JSON document:
//   {"format": "mmm-radiograph-pair", "version": 1,
//    "calibration": <the view sidecar of projection.h, as an object>,
//    "images": {"frontal.png": {"sha256": "<hex>", "png_base64": "..."}, ...}}
// Each sidecar view names its image; every image named is present, is a
// grayscale PNG whose size is the view's, and matches its SHA-256.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/image/image.h"
#include "core/image/projection.h"

namespace mmm::image {

// Where an image came from, when not from a PNG: a DICOM radiograph's
// display window and the hash of its SOP Instance UID (never the UID), so
// that an auditor can match the images used with the originals.
struct ImageOrigin {
  double window_centre = 0.0;  // in the PNG's 16-bit units
  double window_width = 0.0;   // > 0
  std::string sop_instance_uid_sha256;
  friend bool operator==(const ImageOrigin&, const ImageOrigin&) = default;
};

struct RadiographPair {
  std::vector<RadiographFile> views;
  std::map<std::string, std::string> images;  // image name -> PNG file bytes
  // Image name -> origin, for the images read from DICOM (serialised as
  // "window": [centre, width] and "sop_instance_uid_sha256" beside the PNG).
  std::map<std::string, ImageOrigin> origins;

  // The view called `name`; throws InvalidInputError listing the names.
  [[nodiscard]] const RadiographFile& view(const std::string& name) const;
  // The calibrated views alone, in order.
  [[nodiscard]] std::vector<RadiographView> calibrated_views() const;
  // SHA-256 (hex) of the PNG bytes of view `name`'s image.
  [[nodiscard]] std::string image_sha256(const std::string& name) const;
  // The decoded 16-bit grayscale image of view `name` (8-bit files widened).
  [[nodiscard]] GrayImage16 image(const std::string& name) const;
};

// Reads a view sidecar (views.json) and the images it names, relative to its
// folder. Throws IoError naming the file at fault: unreadable sidecar or
// image, an image that is not a grayscale PNG, or whose size differs from its
// view's ("frontal.png is 970 x 2839 pixels, the calibration says 971 x 2839").
RadiographPair load_radiograph_pair(const std::filesystem::path& sidecar);

// The same from images given by view name (e.g. artifacts of a study whose
// file names are lost): each view's image is renamed "<view>.png".
RadiographPair make_radiograph_pair(std::vector<RadiographFile> views,
                                    const std::map<std::string, std::string>& png_by_view,
                                    const std::filesystem::path& source);

std::string radiograph_pair_to_json_text(const RadiographPair& pair);

// Parses and checks a serialised pair; errors are IoErrors naming `source`
// and the field.
RadiographPair radiograph_pair_from_json_text(const std::string& text,
                                              const std::filesystem::path& source);

}  // namespace mmm::image

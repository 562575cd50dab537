// DICOM radiographs (the structure walk, then GDCM) and their de-identified
// forms, one image or a series, as a study stores them.
#include <exception>
#include <string>

#include "core/image/deidentified_radiograph.h"
#include "core/image/dicom_radiograph.h"
#include "core/image/dicom_series.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"

namespace mmm::fuzz {

void dicom(const std::uint8_t* data, std::size_t size) {
  try {
    (void)image::read_dicom_radiograph(as_text(data, size), "input.dcm");
  } catch (const std::exception&) {
  }
}

void deidentified(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = as_text(data, size);
  try {
    if (image::is_deidentified_series(text)) {
      (void)image::deidentified_series_from_text(text, "series.json");
    } else {
      (void)image::deidentified_radiograph_from_text(text, "radiograph.json");
    }
  } catch (const std::exception&) {
  }
}

}  // namespace mmm::fuzz

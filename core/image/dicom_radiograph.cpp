// Reading DICOM radiographs through GDCM (Debian's libgdcm-dev), which parses
// the data set and decodes the pixel data. This file checks the attributes
// before any pixel is decoded, parses the kept ones strictly (GDCM's own
// accessors accept "abc" as a spacing of 0), maps the values onto 16 bits and
// picks the window.

#include "core/image/dicom_radiograph.h"

#include <gdcmByteValue.h>
#include <gdcmDataElement.h>
#include <gdcmDataSet.h>
#include <gdcmFileMetaInformation.h>
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmTag.h>
#include <gdcmTrace.h>
#include <gdcmTransferSyntax.h>
#include <gdcmUIDs.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <istream>
#include <mutex>
#include <streambuf>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/hash/sha256.h"
#include "core/image/dicom_structure.h"
#include "core/image/file_bytes.h"
#include "core/process/isolated_run.h"

namespace mmm::image {

namespace fs = std::filesystem;

namespace {

// An attribute: its tag and its name in PS3.6, for messages.
struct Attribute {
  std::uint16_t group;
  std::uint16_t element;
  const char* name;
  [[nodiscard]] gdcm::Tag tag() const { return {group, element}; }
};

constexpr Attribute kTransferSyntaxUid{0x0002, 0x0010, "Transfer Syntax UID"};
constexpr Attribute kMediaSopClassUid{0x0002, 0x0002, "Media Storage SOP Class UID"};
constexpr Attribute kMediaSopInstanceUid{0x0002, 0x0003, "Media Storage SOP Instance UID"};
constexpr Attribute kSopClassUid{0x0008, 0x0016, "SOP Class UID"};
constexpr Attribute kSopInstanceUid{0x0008, 0x0018, "SOP Instance UID"};
constexpr Attribute kModality{0x0008, 0x0060, "Modality"};
constexpr Attribute kDistanceSourceToDetector{0x0018, 0x1110, "Distance Source to Detector"};
constexpr Attribute kDistanceSourceToPatient{0x0018, 0x1111, "Distance Source to Patient"};
constexpr Attribute kMagnification{0x0018, 0x1114, "Estimated Radiographic Magnification Factor"};
constexpr Attribute kImagerPixelSpacing{0x0018, 0x1164, "Imager Pixel Spacing"};
constexpr Attribute kViewPosition{0x0018, 0x5101, "View Position"};
constexpr Attribute kPatientOrientation{0x0020, 0x0020, "Patient Orientation"};
constexpr Attribute kImageLaterality{0x0020, 0x0062, "Image Laterality"};
constexpr Attribute kSamplesPerPixel{0x0028, 0x0002, "Samples per Pixel"};
constexpr Attribute kPhotometric{0x0028, 0x0004, "Photometric Interpretation"};
constexpr Attribute kNumberOfFrames{0x0028, 0x0008, "Number of Frames"};
constexpr Attribute kRows{0x0028, 0x0010, "Rows"};
constexpr Attribute kColumns{0x0028, 0x0011, "Columns"};
constexpr Attribute kPixelSpacing{0x0028, 0x0030, "Pixel Spacing"};
constexpr Attribute kCalibrationType{0x0028, 0x0A02, "Pixel Spacing Calibration Type"};
constexpr Attribute kBitsAllocated{0x0028, 0x0100, "Bits Allocated"};
constexpr Attribute kBitsStored{0x0028, 0x0101, "Bits Stored"};
constexpr Attribute kHighBit{0x0028, 0x0102, "High Bit"};
constexpr Attribute kPixelRepresentation{0x0028, 0x0103, "Pixel Representation"};
constexpr Attribute kWindowCenter{0x0028, 0x1050, "Window Center"};
constexpr Attribute kWindowWidth{0x0028, 0x1051, "Window Width"};
constexpr Attribute kRescaleIntercept{0x0028, 0x1052, "Rescale Intercept"};
constexpr Attribute kRescaleSlope{0x0028, 0x1053, "Rescale Slope"};
constexpr Attribute kModalityLutSequence{0x0028, 0x3000, "Modality LUT Sequence"};
constexpr Attribute kPixelData{0x7FE0, 0x0010, "Pixel Data"};

// A kept string longer than this is refused: every kept attribute is a CS or
// UI of at most 16 or 64 characters per value, so a longer one is a damaged
// (or hostile) file, not a radiograph to show.
constexpr std::size_t kMaxKeptText = 256;

// Radiograph SOP classes (PS3.4 B.5): CR, DX for presentation and for
// processing, secondary capture (single-frame, and the multi-frame grayscale
// ones with one frame).
constexpr std::array<const char*, 6> kRadiographSopClasses = {
    "1.2.840.10008.5.1.4.1.1.1", "1.2.840.10008.5.1.4.1.1.1.1", "1.2.840.10008.5.1.4.1.1.1.1.1",
    "1.2.840.10008.5.1.4.1.1.7", "1.2.840.10008.5.1.4.1.1.7.2", "1.2.840.10008.5.1.4.1.1.7.3"};

std::string hex4(std::uint16_t value) {
  constexpr std::string_view kDigits = "0123456789ABCDEF";
  std::string out(4, '0');
  for (int i = 3; i >= 0; --i) {
    out[static_cast<std::size_t>(i)] = kDigits[value & 0xFU];
    value = static_cast<std::uint16_t>(value >> 4U);
  }
  return out;
}

// "Imager Pixel Spacing (0018,1164)".
std::string tag_label(const Attribute& attribute) {
  return std::string(attribute.name) + " (" + hex4(attribute.group) + "," +
         hex4(attribute.element) + ")";
}

[[noreturn]] void fail_at(const fs::path& source, const Attribute& attribute,
                          const std::string& problem) {
  throw IoError(source, tag_label(attribute) + " " + problem);
}

// A std::streambuf reading bytes held elsewhere, without copying them (up to
// kDicomMaxFileBytes), for GDCM's stream interface.
class ByteViewBuffer : public std::streambuf {
 public:
  explicit ByteViewBuffer(std::string_view bytes) {
    // The get area is only ever read; std::streambuf wants non-const pointers.
    char* begin = const_cast<char*>(bytes.data());
    setg(begin, begin, begin + bytes.size());
  }

 protected:
  std::streamsize xsgetn(char* out, std::streamsize count) override {
    const std::streamsize n = std::min(count, static_cast<std::streamsize>(egptr() - gptr()));
    if (n > 0) {
      std::memcpy(out, gptr(), static_cast<std::size_t>(n));
      setg(eback(), gptr() + n, egptr());
    }
    return n;
  }
  pos_type seekoff(off_type offset, std::ios_base::seekdir direction,
                   std::ios_base::openmode which) override {
    if ((which & std::ios_base::in) == 0) return {off_type(-1)};
    const off_type size = egptr() - eback();
    off_type base = 0;
    if (direction == std::ios_base::cur) base = gptr() - eback();
    if (direction == std::ios_base::end) base = size;
    const off_type target = base + offset;
    if (target < 0 || target > size) return {off_type(-1)};
    setg(eback(), eback() + target, egptr());
    return {target};
  }
  pos_type seekpos(pos_type position, std::ios_base::openmode which) override {
    return seekoff(off_type(position), std::ios_base::beg, which);
  }
};

// GDCM reports through global streams (stderr by default); every problem it
// reports is turned into an IoError here, so its messages are switched off
// once for the process instead of interleaving with the server's log.
void silence_gdcm() {
  static std::once_flag once;
  std::call_once(once, [] {
    gdcm::Trace::DebugOff();
    gdcm::Trace::WarningOff();
    gdcm::Trace::ErrorOff();
  });
}

// The value of a string attribute without DICOM's padding (trailing spaces
// and NULs, leading spaces); nullopt when absent or empty.
std::optional<std::string> text_of(const gdcm::DataSet& data_set, const Attribute& attribute,
                                   const fs::path& source) {
  if (!data_set.FindDataElement(attribute.tag())) return std::nullopt;
  const gdcm::DataElement& element = data_set.GetDataElement(attribute.tag());
  const gdcm::ByteValue* value = element.GetByteValue();
  if (element.IsEmpty() || value == nullptr || value->GetLength() == 0) return std::nullopt;
  if (value->GetLength() > kMaxKeptText) {
    fail_at(source, attribute,
            "is " + std::to_string(value->GetLength()) +
                " bytes long, more than any valid value (" + std::to_string(kMaxKeptText) +
                "): the file is damaged");
  }
  std::string text(value->GetPointer(), value->GetLength());
  while (!text.empty() && (text.back() == ' ' || text.back() == '\0')) text.pop_back();
  const std::size_t first = text.find_first_not_of(' ');
  if (first == std::string::npos) return std::nullopt;
  return text.substr(first);
}

// An unsigned short (US) attribute, as GDCM holds it (host byte order, also
// for the big-endian transfer syntax); nullopt when absent.
std::optional<int> us_of(const gdcm::DataSet& data_set, const Attribute& attribute,
                         const fs::path& source) {
  if (!data_set.FindDataElement(attribute.tag())) return std::nullopt;
  const gdcm::ByteValue* value = data_set.GetDataElement(attribute.tag()).GetByteValue();
  if (value == nullptr || value->GetLength() == 0) return std::nullopt;
  if (value->GetLength() != 2) {
    fail_at(source, attribute,
            "holds " + std::to_string(value->GetLength()) +
                " bytes, expected one unsigned short (2 bytes): the file is damaged");
  }
  std::uint16_t number = 0;
  std::memcpy(&number, value->GetPointer(), 2);
  return number;
}

int required_us(const gdcm::DataSet& data_set, const Attribute& attribute, const fs::path& source) {
  const std::optional<int> value = us_of(data_set, attribute, source);
  if (!value) fail_at(source, attribute, "is missing; an image must have it (the file is damaged)");
  return *value;
}

// The values of a decimal string (DS) attribute: each of the backslash-
// separated values must be a finite decimal number ("abc", "", "inf" are
// refused). Empty when the attribute is absent or empty.
std::vector<double> ds_values(const gdcm::DataSet& data_set, const Attribute& attribute,
                              const fs::path& source) {
  const std::optional<std::string> text = text_of(data_set, attribute, source);
  std::vector<double> values;
  if (!text) return values;
  std::size_t start = 0;
  while (start <= text->size()) {
    std::size_t end = text->find('\\', start);
    if (end == std::string::npos) end = text->size();
    std::string_view item(text->data() + start, end - start);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    std::string_view digits = item;
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);  // DS allows '+'
    double number = 0.0;
    const auto [end_ptr, error] =
        std::from_chars(digits.data(), digits.data() + digits.size(), number);
    if (digits.empty() || error != std::errc() || end_ptr != digits.data() + digits.size() ||
        !std::isfinite(number)) {
      fail_at(source, attribute,
              "value " + std::to_string(values.size() + 1) + " '" + std::string(item) +
                  "' is not a finite decimal number (DS): the file is malformed (correct the "
                  "attribute, e.g. with dcmodify, or export the image again)");
    }
    values.push_back(number);
    start = end + 1;
  }
  return values;
}

// A spacing pair (row\column) of positive millimetres.
std::optional<PixelSpacingMm> spacing_of(const gdcm::DataSet& data_set, const Attribute& attribute,
                                         const fs::path& source) {
  const std::vector<double> values = ds_values(data_set, attribute, source);
  if (values.empty()) return std::nullopt;
  if (values.size() != 2) {
    fail_at(source, attribute,
            "holds " + std::to_string(values.size()) +
                " values, expected 2 (row spacing\\column spacing, mm)");
  }
  for (const double value : values) {
    if (value <= 0.0) {
      fail_at(source, attribute,
              "holds a spacing of " + std::to_string(value) +
                  " mm; a spacing must be > 0 (the file is malformed)");
    }
  }
  return PixelSpacingMm{values[0], values[1]};
}

// A single positive DS value (a distance or a factor).
std::optional<double> positive_of(const gdcm::DataSet& data_set, const Attribute& attribute,
                                  const fs::path& source) {
  const std::vector<double> values = ds_values(data_set, attribute, source);
  if (values.empty()) return std::nullopt;
  if (values.size() != 1) {
    fail_at(source, attribute, "holds " + std::to_string(values.size()) + " values, expected 1");
  }
  if (values[0] <= 0.0) {
    fail_at(source, attribute,
            "is " + std::to_string(values[0]) + "; it must be > 0 (the file is malformed)");
  }
  return values[0];
}

bool is_orientation_code(const std::string& code) {
  return !code.empty() && code.find_first_not_of("APRLHF") == std::string::npos;
}

std::optional<std::array<std::string, 2>> orientation_of(const gdcm::DataSet& data_set,
                                                         const fs::path& source) {
  const std::optional<std::string> text = text_of(data_set, kPatientOrientation, source);
  if (!text) return std::nullopt;
  const std::size_t split = text->find('\\');
  std::array<std::string, 2> codes;
  if (split != std::string::npos) {
    codes = {text->substr(0, split), text->substr(split + 1)};
  }
  for (std::string& code : codes) {
    while (!code.empty() && code.back() == ' ') code.pop_back();
    while (!code.empty() && code.front() == ' ') code.erase(code.begin());
  }
  if (split == std::string::npos || !is_orientation_code(codes[0]) ||
      !is_orientation_code(codes[1])) {
    fail_at(source, kPatientOrientation,
            "is '" + *text +
                "'; expected two directions made of A, P, R, L, H, F (row\\column, e.g. L\\F)");
  }
  return codes;
}

std::optional<std::string> laterality_of(const gdcm::DataSet& data_set, const fs::path& source) {
  std::optional<std::string> text = text_of(data_set, kImageLaterality, source);
  if (text && *text != "R" && *text != "L" && *text != "U" && *text != "B") {
    fail_at(source, kImageLaterality,
            "is '" + *text + "'; expected R, L, U (unpaired) or B (both)");
  }
  return text;
}

std::string uid_name(const std::string& uid) {
  gdcm::UIDs known;
  if (known.SetFromUID(uid.c_str()) && known.GetName() != nullptr) return known.GetName();
  return "not a UID GDCM knows";
}

// The transfer syntax of the file: from the file meta information (known to
// GDCM: check_dicom_structure refused others), or the one GDCM settled on for
// a bare data set (implicit VR little endian).
std::string transfer_syntax_of(const gdcm::File& file, const fs::path& source) {
  if (std::optional<std::string> declared = text_of(file.GetHeader(), kTransferSyntaxUid, source)) {
    return *declared;
  }
  const char* used = file.GetHeader().GetDataSetTransferSyntax().GetString();
  return used != nullptr ? used : "";
}

// Checks the image attributes before any pixel is decoded.
struct PixelLayout {
  int rows = 0;
  int columns = 0;
  int bits_allocated = 16;
  int bits_stored = 16;
  bool is_signed = false;
  bool monochrome1 = false;
};

PixelLayout check_layout(const gdcm::DataSet& data_set, const fs::path& source) {
  PixelLayout layout;
  const int samples = required_us(data_set, kSamplesPerPixel, source);
  const std::string photometric = text_of(data_set, kPhotometric, source).value_or("");
  if (samples != 1 || (photometric != "MONOCHROME1" && photometric != "MONOCHROME2")) {
    throw IoError(source, tag_label(kSamplesPerPixel) + " is " + std::to_string(samples) + " and " +
                              tag_label(kPhotometric) + " '" + photometric +
                              "'; a radiograph is grayscale: 1 sample, MONOCHROME1 or "
                              "MONOCHROME2 (was the image exported as a colour screenshot? "
                              "export the original DX/CR image)");
  }
  layout.monochrome1 = photometric == "MONOCHROME1";
  layout.rows = required_us(data_set, kRows, source);
  layout.columns = required_us(data_set, kColumns, source);
  const std::array<std::pair<Attribute, int>, 2> sides{
      {{kRows, layout.rows}, {kColumns, layout.columns}}};
  for (const auto& [attribute, value] : sides) {
    if (value == 0 || value > kDicomMaxSide) {
      fail_at(source, attribute,
              "is " + std::to_string(value) + "; expected 1 to " + std::to_string(kDicomMaxSide) +
                  " pixels (an empty or implausibly large image)");
    }
  }
  layout.bits_allocated = required_us(data_set, kBitsAllocated, source);
  if (layout.bits_allocated != 8 && layout.bits_allocated != 16) {
    fail_at(source, kBitsAllocated,
            "is " + std::to_string(layout.bits_allocated) + "; supported are 8 and 16");
  }
  layout.bits_stored = required_us(data_set, kBitsStored, source);
  if (layout.bits_stored < 8 || layout.bits_stored > layout.bits_allocated) {
    fail_at(source, kBitsStored,
            "is " + std::to_string(layout.bits_stored) + "; supported are 8 to " +
                std::to_string(layout.bits_allocated) + " (Bits Allocated)");
  }
  if (const std::optional<int> high_bit = us_of(data_set, kHighBit, source);
      high_bit && *high_bit != layout.bits_stored - 1) {
    fail_at(source, kHighBit,
            "is " + std::to_string(*high_bit) + "; only Bits Stored - 1 (" +
                std::to_string(layout.bits_stored - 1) + ", the low bits) is supported");
  }
  const int representation = us_of(data_set, kPixelRepresentation, source).value_or(0);
  if (representation != 0 && representation != 1) {
    fail_at(source, kPixelRepresentation,
            "is " + std::to_string(representation) + "; expected 0 (unsigned) or 1 (signed)");
  }
  layout.is_signed = representation == 1;
  if (const std::vector<double> frames = ds_values(data_set, kNumberOfFrames, source);
      !frames.empty() && frames[0] != 1.0) {
    fail_at(source, kNumberOfFrames,
            "is " + std::to_string(frames[0]) +
                "; a radiograph has one frame (export the frame "
                "to load as its own image)");
  }
  if (data_set.FindDataElement(kModalityLutSequence.tag())) {
    fail_at(source, kModalityLutSequence,
            "is present: non-linear modality LUTs are not supported (export the image with "
            "Rescale Slope/Intercept, or as 'for presentation')");
  }
  return layout;
}

struct Window {
  double centre = 0.0;
  double width = 0.0;
};

// Window Center / Width (first value of each), in modality units.
std::optional<Window> file_window(const gdcm::DataSet& data_set, const fs::path& source) {
  const std::vector<double> centres = ds_values(data_set, kWindowCenter, source);
  const std::vector<double> widths = ds_values(data_set, kWindowWidth, source);
  if (centres.empty() && widths.empty()) return std::nullopt;
  if (centres.empty() || widths.empty()) {
    throw IoError(source, tag_label(centres.empty() ? kWindowWidth : kWindowCenter) +
                              " is present without " +
                              tag_label(centres.empty() ? kWindowCenter : kWindowWidth) +
                              "; a window needs both (the file is malformed)");
  }
  if (widths[0] < 1.0) {
    fail_at(source, kWindowWidth,
            "is " + std::to_string(widths[0]) + "; a window width must be >= 1 (PS3.3 C.11.2.1.2)");
  }
  return Window{centres[0], widths[0]};
}

// The stored sample i of the decoded buffer, masked to Bits Stored and
// sign-extended when signed (bits above Bits Stored may hold overlays).
std::int32_t stored_sample(const std::vector<char>& raw, std::size_t i, const PixelLayout& layout) {
  std::uint32_t bits = 0;
  if (layout.bits_allocated == 8) {
    bits = static_cast<std::uint8_t>(raw[i]);
  } else {
    std::uint16_t word = 0;
    std::memcpy(&word, raw.data() + 2 * i, 2);  // GDCM decodes to host byte order
    bits = word;
  }
  const auto width = static_cast<std::uint32_t>(layout.bits_stored);
  bits &= (std::uint32_t{1} << width) - 1U;
  auto value = static_cast<std::int32_t>(bits);
  if (layout.is_signed && (bits >> (width - 1U)) != 0U) {
    value -= static_cast<std::int32_t>(std::uint32_t{1} << width);
  }
  return value;
}

// 0.5 and 99.5 percentiles of the 16-bit image (ranks floor(0.005 (n - 1))
// and ceil(0.995 (n - 1)) of the sorted samples), from a histogram: the
// usual automatic window of radiograph viewers, which ignores collimator
// edges and burnt-out background.
DicomWindow percentile_window(const GrayImage16& image) {
  std::vector<std::size_t> histogram(65536, 0);
  for (const std::uint16_t sample : image.pixels) ++histogram[sample];
  const std::size_t last = image.pixels.size() - 1;
  const auto low_rank = static_cast<std::size_t>(std::floor(0.005 * static_cast<double>(last)));
  const auto high_rank = static_cast<std::size_t>(std::ceil(0.995 * static_cast<double>(last)));
  auto sample_at = [&histogram](std::size_t rank) {
    std::size_t seen = 0;
    for (std::size_t value = 0; value < histogram.size(); ++value) {
      seen += histogram[value];
      if (seen > rank) return static_cast<double>(value);
    }
    return 65535.0;
  };
  const double low = sample_at(low_rank);
  const double high = sample_at(high_rank);
  return {(low + high) / 2.0, std::max(high - low, 1.0), DicomWindowSource::kPercentiles};
}

}  // namespace

bool looks_like_dicom(std::string_view bytes) {
  if (bytes.size() >= 132 && bytes.substr(128, 4) == "DICM") return true;
  if (bytes.size() < 8) return false;
  const auto group = static_cast<std::uint16_t>(static_cast<std::uint8_t>(bytes[0]) |
                                                (static_cast<std::uint8_t>(bytes[1]) << 8U));
  return group == 0x0002 || group == 0x0008;
}

namespace {

// What read_dicom_radiograph() does once the file was decoded safely in a
// child process: the same decoding, in this one.
DicomRadiograph decode_dicom_radiograph(std::string_view bytes, const fs::path& source);

}  // namespace

DicomRadiograph read_dicom_radiograph(std::string_view bytes, const fs::path& source) {
  if (bytes.size() > kDicomMaxFileBytes) {
    throw IoError(source, "is " + std::to_string(bytes.size() >> 20U) + " MiB, above the " +
                              std::to_string(kDicomMaxFileBytes >> 20U) +
                              " MiB limit for one radiograph (a multi-frame series? export "
                              "the single image)");
  }
  if (!looks_like_dicom(bytes)) {
    throw IoError(source,
                  "is not a DICOM file: no \"DICM\" at byte 128 and no data set at byte 0 "
                  "(expected a DICOM Part 10 file as exported by the PACS, not a picture or a "
                  "report)");
  }
  // Truncated and malformed files make GDCM abort (dicom_structure.h): the
  // walk refuses them with a message naming the element.
  detail::check_dicom_structure(bytes, source);
  // What the walk does not catch (an attribute of the wrong VR, a broken
  // compressed stream) GDCM or its codecs may still abort on: decode first in
  // a child process (isolated_run.h), here only once that came through.
  const process::IsolatedOutcome trial = process::run_isolated(
      [&] { (void)decode_dicom_radiograph(bytes, source); }, kDicomDecodeTimeLimit);
  if (!trial.came_through) {
    throw IoError(source, "could not be decoded: the DICOM library " + trial.description() +
                              " reading it; the file is malformed (or, if it took too long, "
                              "too large); hint: export the image again from the modality or "
                              "the PACS");
  }
  return decode_dicom_radiograph(bytes, source);
}

namespace {

DicomRadiograph decode_dicom_radiograph(std::string_view bytes, const fs::path& source) {
  silence_gdcm();
  ByteViewBuffer buffer(bytes);
  std::istream stream(&buffer);
  gdcm::ImageReader reader;
  reader.SetStream(stream);
  bool parsed = false;
  std::string gdcm_problem;
  try {
    parsed = reader.Read();
  } catch (const std::exception& error) {
    gdcm_problem = std::string(" (GDCM: ") + error.what() + ")";
  }
  const gdcm::File& file = reader.GetFile();
  const gdcm::DataSet& data_set = file.GetDataSet();

  DicomRadiograph out;
  out.transfer_syntax_uid = transfer_syntax_of(file, source);
  if (data_set.IsEmpty()) {
    throw IoError(source, "is corrupt: GDCM could not parse its data set" + gdcm_problem);
  }

  std::optional<std::string> sop_class = text_of(data_set, kSopClassUid, source);
  if (!sop_class) sop_class = text_of(file.GetHeader(), kMediaSopClassUid, source);
  if (!sop_class) fail_at(source, kSopClassUid, "is missing; a DICOM image always has one");
  if (std::find_if(kRadiographSopClasses.begin(), kRadiographSopClasses.end(),
                   [&](const char* uid) { return *sop_class == uid; }) ==
      kRadiographSopClasses.end()) {
    fail_at(source, kSopClassUid,
            "'" + *sop_class + "' (" + uid_name(*sop_class) +
                ") is not a projection radiograph; supported are CR, DX (for presentation or "
                "processing) and secondary capture images");
  }
  out.sop_class_uid = *sop_class;

  const PixelLayout layout = check_layout(data_set, source);
  if (!data_set.FindDataElement(kPixelData.tag()) ||
      data_set.GetDataElement(kPixelData.tag()).IsEmpty()) {
    fail_at(source, kPixelData,
            "is missing: the file holds no image (a report, a presentation state or a header-only "
            "export? export the image itself)");
  }
  if (!parsed) {
    throw IoError(source, "GDCM could not read the image" + gdcm_problem + ": the file is corrupt");
  }

  out.modality = text_of(data_set, kModality, source).value_or("");
  out.photometric_interpretation = layout.monochrome1 ? "MONOCHROME1" : "MONOCHROME2";
  out.bits_stored = layout.bits_stored;
  out.pixel_signed = layout.is_signed;
  out.rows = layout.rows;
  out.columns = layout.columns;
  std::optional<std::string> instance = text_of(data_set, kSopInstanceUid, source);
  if (!instance) instance = text_of(file.GetHeader(), kMediaSopInstanceUid, source);
  if (!instance) fail_at(source, kSopInstanceUid, "is missing; a DICOM image always has one");
  out.sop_instance_uid_sha256 = hash::sha256_hex(*instance);

  if (const std::vector<double> slope = ds_values(data_set, kRescaleSlope, source);
      !slope.empty()) {
    if (slope[0] == 0.0) fail_at(source, kRescaleSlope, "is 0: every pixel would have one value");
    out.rescale_slope = slope[0];
  }
  if (const std::vector<double> intercept = ds_values(data_set, kRescaleIntercept, source);
      !intercept.empty()) {
    out.rescale_intercept = intercept[0];
  }
  const std::optional<Window> window = file_window(data_set, source);

  out.imager_pixel_spacing = spacing_of(data_set, kImagerPixelSpacing, source);
  out.pixel_spacing = spacing_of(data_set, kPixelSpacing, source);
  out.magnification_factor = positive_of(data_set, kMagnification, source);
  out.distance_source_to_detector_mm = positive_of(data_set, kDistanceSourceToDetector, source);
  out.distance_source_to_patient_mm = positive_of(data_set, kDistanceSourceToPatient, source);
  if (out.distance_source_to_detector_mm && out.distance_source_to_patient_mm &&
      *out.distance_source_to_patient_mm > *out.distance_source_to_detector_mm) {
    fail_at(source, kDistanceSourceToPatient,
            "(" + std::to_string(*out.distance_source_to_patient_mm) + " mm) exceeds " +
                tag_label(kDistanceSourceToDetector) + " (" +
                std::to_string(*out.distance_source_to_detector_mm) +
                " mm): the patient cannot be beyond the detector");
  }
  out.view_position = text_of(data_set, kViewPosition, source);
  out.patient_orientation = orientation_of(data_set, source);
  out.image_laterality = laterality_of(data_set, source);
  out.pixel_spacing_calibration_type = text_of(data_set, kCalibrationType, source);

  // Decode: the size GDCM will write is checked against the attributes
  // (already within kDicomMaxSide) before the buffer is allocated.
  const gdcm::Image& image = reader.GetImage();
  const std::size_t pixel_count =
      static_cast<std::size_t>(layout.rows) * static_cast<std::size_t>(layout.columns);
  const std::size_t expected = pixel_count * static_cast<std::size_t>(layout.bits_allocated / 8);
  if (image.GetBufferLength() != expected) {
    fail_at(source, kPixelData,
            "decodes to " + std::to_string(image.GetBufferLength()) +
                " bytes, but Rows x Columns x "
                "Bits Allocated say " +
                std::to_string(expected) + ": the file is inconsistent");
  }
  std::vector<char> raw(expected);
  if (!image.GetBuffer(raw.data())) {
    fail_at(source, kTransferSyntaxUid,
            "'" + out.transfer_syntax_uid + "' (" + uid_name(out.transfer_syntax_uid) +
                "): GDCM could not decode the Pixel Data (7FE0,0010) in it (damaged, or a codec "
                "this build lacks); convert it, e.g. `gdcmconv --raw in.dcm out.dcm`");
  }

  // Modality values are stored * slope + intercept: monotonic, so their
  // range comes from the range of the stored values.
  std::int32_t stored_min = INT32_MAX;
  std::int32_t stored_max = INT32_MIN;
  for (std::size_t i = 0; i < pixel_count; ++i) {
    const std::int32_t value = stored_sample(raw, i, layout);
    stored_min = std::min(stored_min, value);
    stored_max = std::max(stored_max, value);
  }
  const double slope = out.rescale_slope;
  const double intercept = out.rescale_intercept;
  const double value_a = stored_min * slope + intercept;
  const double value_b = stored_max * slope + intercept;
  const double value_min = std::min(value_a, value_b);
  const double value_range = std::max(value_a, value_b) - value_min;
  out.value_map = {value_min, value_range > 0.0 ? 65535.0 / value_range : 1.0, layout.monochrome1};
  // Unsigned 16-bit samples without a rescale keep their values: the image
  // is the file's, sample for sample, as a 16-bit PNG of it would be.
  if (layout.bits_stored == 16 && !out.pixel_signed && slope == 1.0 && intercept == 0.0) {
    out.value_map = {0.0, 1.0, layout.monochrome1};
  }

  out.image = GrayImage16(layout.columns, layout.rows);
  const DicomValueMap& map = out.value_map;
  for (std::size_t i = 0; i < pixel_count; ++i) {
    const double value = stored_sample(raw, i, layout) * slope + intercept;
    const double s = std::clamp(std::round((value - map.value_min) * map.scale), 0.0, 65535.0);
    out.image.pixels[i] = static_cast<std::uint16_t>(map.inverted ? 65535.0 - s : s);
  }

  if (window) {
    const double s = (window->centre - map.value_min) * map.scale;
    out.window = {map.inverted ? 65535.0 - s : s, window->width * map.scale,
                  DicomWindowSource::kFile};
  } else {
    out.window = percentile_window(out.image);
  }
  return out;
}

}  // namespace

DicomRadiograph read_dicom_radiograph(const fs::path& path) {
  const std::string bytes = detail::read_file_bytes(path, "a DICOM file", kDicomMaxFileBytes);
  return read_dicom_radiograph(bytes, path);
}

namespace {

bool nearly_equal(const PixelSpacingMm& a, const PixelSpacingMm& b) {
  // Relative 1e-4: the same spacing written with different numbers of digits
  // ("0.139" vs "0.1390000") is one spacing; a calibration changes it by a
  // magnification of at least a few per cent.
  for (std::size_t i = 0; i < 2; ++i) {
    if (std::abs(a[i] - b[i]) > 1e-4 * std::max(a[i], b[i])) return false;
  }
  return true;
}

PixelSpacingMm scaled(const PixelSpacingMm& spacing, double factor) {
  return {spacing[0] * factor, spacing[1] * factor};
}

}  // namespace

RadiographSpacing radiograph_spacing(const DicomRadiograph& radiograph) {
  RadiographSpacing out;
  std::string magnification_from;
  if (radiograph.magnification_factor) {
    out.magnification = radiograph.magnification_factor;
    magnification_from = "Estimated Radiographic Magnification Factor (0018,1114)";
  } else if (radiograph.distance_source_to_detector_mm &&
             radiograph.distance_source_to_patient_mm) {
    out.magnification =
        *radiograph.distance_source_to_detector_mm / *radiograph.distance_source_to_patient_mm;
    magnification_from =
        "Distance Source to Detector / to Patient (0018,1110 / 0018,1111), the magnification "
        "at the isocentre";
  }
  const auto& imager = radiograph.imager_pixel_spacing;
  const auto& pixel = radiograph.pixel_spacing;
  const bool has_calibration_type = radiograph.pixel_spacing_calibration_type.has_value();
  const std::string calibration = has_calibration_type
                                      ? " (Pixel Spacing Calibration Type (0028,0A02) " +
                                            *radiograph.pixel_spacing_calibration_type + ")"
                                      : "";

  if (imager && pixel && (has_calibration_type || !nearly_equal(*imager, *pixel))) {
    out.meaning = SpacingMeaning::kCalibratedToPatient;
    out.detector_mm = imager;
    out.patient_mm = pixel;
    if (!out.magnification) {
      out.magnification = ((*imager)[0] / (*pixel)[0] + (*imager)[1] / (*pixel)[1]) / 2.0;
      magnification_from = "Imager Pixel Spacing / Pixel Spacing";
    }
    out.explanation = "Pixel Spacing (0028,0030) is calibrated to the patient plane" + calibration +
                      ": it differs from Imager Pixel Spacing (0018,1164), which is at the "
                      "detector (PS3.3 10.7.1.3).";
  } else if (imager) {
    out.meaning = SpacingMeaning::kDetector;
    out.detector_mm = imager;
    out.explanation =
        std::string("Imager Pixel Spacing (0018,1164) is at the detector's front plane") +
        (pixel ? "; Pixel Spacing (0028,0030) equals it, so it is not calibrated (PS3.3 "
                 "10.7.1.3)"
               : "") +
        ".";
    if (out.magnification) out.patient_mm = scaled(*imager, 1.0 / *out.magnification);
  } else if (pixel && has_calibration_type) {
    out.meaning = SpacingMeaning::kCalibratedToPatient;
    out.patient_mm = pixel;
    if (out.magnification) out.detector_mm = scaled(*pixel, *out.magnification);
    out.explanation = "Pixel Spacing (0028,0030) is calibrated to the patient plane" + calibration +
                      "; the file has no Imager Pixel Spacing (0018,1164).";
  } else if (pixel) {
    out.meaning = SpacingMeaning::kUnknownPlane;
    out.explanation =
        "Only Pixel Spacing (0028,0030), without Imager Pixel Spacing (0018,1164) or a "
        "calibration type: whether it is at the detector or at the patient cannot be told "
        "(secondary capture, older CR); calibrate the view rather than trust it.";
    return out;
  } else {
    out.explanation =
        "No Imager Pixel Spacing (0018,1164) or Pixel Spacing (0028,0030): the image has no "
        "physical scale; calibrate the view.";
    return out;
  }
  if (out.magnification) {
    out.explanation += " Magnification " + std::to_string(*out.magnification) + " from " +
                       magnification_from + ".";
  } else if (!out.patient_mm) {
    out.explanation +=
        " No magnification factor or source distances: the spacing at the patient is unknown.";
  }
  return out;
}

}  // namespace mmm::image

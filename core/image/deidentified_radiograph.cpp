// The de-identified radiograph document: written from the fields of
// DicomRadiograph only (so nothing else can leak into it), read back with
// every field checked as strictly as the DICOM reader checks the attributes.

#include "core/image/deidentified_radiograph.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>
#include <variant>

#include "core/base64.h"
#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/hash/sha256.h"
#include "core/image/png.h"

namespace mmm::image {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

constexpr const char* kDeidentifiedFormat = "mmm-deidentified-radiograph";
constexpr int kDeidentifiedVersion = 1;

const char* window_source_name(DicomWindowSource source) {
  return source == DicomWindowSource::kFile ? "file" : "percentiles";
}

// Reads the fields of one JSON object, each checked, and refuses any it
// was not asked for (a misspelt field is an error, not silently dropped).
class Fields {
 public:
  Fields(const Json& object, std::string where, const fs::path& source)
      : object_(object), where_(std::move(where)), source_(source) {
    if (!object_.is_object()) throw IoError(source_, where_ + " must be a JSON object");
  }

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw IoError(source_, "field '" + where_ + key + "' " + problem);
  }

  const Json* find(const std::string& key) {
    seen_.insert(key);
    const auto it = object_.find(key);
    return it == object_.end() ? nullptr : &*it;
  }
  const Json& required(const std::string& key) {
    const Json* value = find(key);
    if (value == nullptr) fail(key, "is missing");
    return *value;
  }

  std::string text(const std::string& key) {
    const Json& value = required(key);
    if (!value.is_string()) fail(key, "must be a string");
    return value.get<std::string>();
  }
  std::optional<std::string> optional_text(const std::string& key) {
    if (find(key) == nullptr) return std::nullopt;
    return text(key);
  }
  bool flag(const std::string& key) {
    const Json& value = required(key);
    if (!value.is_boolean()) fail(key, "must be true or false");
    return value.get<bool>();
  }
  int integer(const std::string& key, int low, int high) {
    const Json& value = required(key);
    if (!value.is_number_integer() || value.get<std::int64_t>() < low ||
        value.get<std::int64_t>() > high) {
      fail(key, "must be an integer from " + std::to_string(low) + " to " + std::to_string(high));
    }
    return value.get<int>();
  }
  double number(const std::string& key) {
    const Json& value = required(key);
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
      fail(key, "must be a finite number");
    }
    return value.get<double>();
  }
  double positive(const std::string& key) {
    const double value = number(key);
    if (value <= 0.0) fail(key, "must be > 0, got " + std::to_string(value));
    return value;
  }
  std::optional<double> optional_positive(const std::string& key) {
    if (find(key) == nullptr) return std::nullopt;
    return positive(key);
  }
  std::optional<PixelSpacingMm> optional_spacing(const std::string& key) {
    const Json* value = find(key);
    if (value == nullptr) return std::nullopt;
    if (!value->is_array() || value->size() != 2) {
      fail(key, "must be [row spacing, column spacing] in mm");
    }
    PixelSpacingMm spacing{};
    for (std::size_t i = 0; i < 2; ++i) {
      const Json& item = (*value)[i];
      if (!item.is_number() || !std::isfinite(item.get<double>()) || item.get<double>() <= 0.0) {
        fail(key, "must hold two finite spacings > 0 (mm)");
      }
      spacing[i] = item.get<double>();
    }
    return spacing;
  }

  // Throws for a field none of the readers above asked for.
  void check_no_others() const {
    for (const auto& item : object_.items()) {
      if (!seen_.contains(item.key())) {
        fail(item.key(), "is not a field of a " + std::string(kDeidentifiedFormat) + " document");
      }
    }
  }

 private:
  const Json& object_;
  std::string where_;
  const fs::path& source_;
  std::set<std::string> seen_;
};

bool is_sha256_hex(const std::string& text) {
  return text.size() == 64 && text.find_first_not_of("0123456789abcdef") == std::string::npos;
}

bool is_orientation_letters(const std::string& code) {
  return !code.empty() && code.find_first_not_of("APRLHF") == std::string::npos;
}

}  // namespace

std::string deidentified_radiograph_text(const DicomRadiograph& radiograph) {
  if (radiograph.image.empty() || radiograph.image.width != radiograph.columns ||
      radiograph.image.height != radiograph.rows) {
    throw InvalidInputError(
        "a de-identified radiograph needs an image of columns x rows (" +
        std::to_string(radiograph.columns) + " x " + std::to_string(radiograph.rows) + "), got " +
        std::to_string(radiograph.image.width) + " x " + std::to_string(radiograph.image.height));
  }
  Json root;
  root["format"] = kDeidentifiedFormat;
  root["version"] = kDeidentifiedVersion;
  root["modality"] = radiograph.modality;
  root["sop_class_uid"] = radiograph.sop_class_uid;
  root["transfer_syntax_uid"] = radiograph.transfer_syntax_uid;
  root["photometric_interpretation"] = radiograph.photometric_interpretation;
  root["bits_stored"] = radiograph.bits_stored;
  root["pixel_signed"] = radiograph.pixel_signed;
  root["rows"] = radiograph.rows;
  root["columns"] = radiograph.columns;
  root["rescale_slope"] = radiograph.rescale_slope;
  root["rescale_intercept"] = radiograph.rescale_intercept;
  root["sop_instance_uid_sha256"] = radiograph.sop_instance_uid_sha256;
  root["value_map"] = {{"value_min", radiograph.value_map.value_min},
                       {"scale", radiograph.value_map.scale},
                       {"inverted", radiograph.value_map.inverted}};
  root["window"] = {{"centre", radiograph.window.centre},
                    {"width", radiograph.window.width},
                    {"source", window_source_name(radiograph.window.source)}};
  auto put_spacing = [&root](const char* key, const std::optional<PixelSpacingMm>& spacing) {
    if (spacing) root[key] = {(*spacing)[0], (*spacing)[1]};
  };
  put_spacing("imager_pixel_spacing_mm", radiograph.imager_pixel_spacing);
  put_spacing("pixel_spacing_mm", radiograph.pixel_spacing);
  auto put = [&root](const char* key, const auto& value) {
    if (value) root[key] = *value;
  };
  put("magnification_factor", radiograph.magnification_factor);
  put("distance_source_to_detector_mm", radiograph.distance_source_to_detector_mm);
  put("distance_source_to_patient_mm", radiograph.distance_source_to_patient_mm);
  put("view_position", radiograph.view_position);
  if (radiograph.patient_orientation) {
    root["patient_orientation"] = {(*radiograph.patient_orientation)[0],
                                   (*radiograph.patient_orientation)[1]};
  }
  put("image_laterality", radiograph.image_laterality);
  put("pixel_spacing_calibration_type", radiograph.pixel_spacing_calibration_type);
  const std::string png = encode_png(radiograph.image);
  root["png_base64"] = base64_encode(png);
  root["sha256"] = hash::sha256_hex(png);
  return root.dump();
}

DicomRadiograph deidentified_radiograph_from_text(std::string_view text, const fs::path& source) {
  Json root;
  try {
    root = parse_json(text, JsonLimits{kDeidentifiedRadiographMaxBytes, 8});
  } catch (const Json::parse_error& error) {
    throw IoError(source, std::string("is not a de-identified radiograph (JSON): ") + error.what());
  }
  Fields fields(root, "", source);
  if (fields.text("format") != kDeidentifiedFormat) {
    fields.fail("format", std::string("must be \"") + kDeidentifiedFormat + "\"");
  }
  fields.integer("version", kDeidentifiedVersion, kDeidentifiedVersion);

  DicomRadiograph out;
  out.modality = fields.text("modality");
  out.sop_class_uid = fields.text("sop_class_uid");
  out.transfer_syntax_uid = fields.text("transfer_syntax_uid");
  out.photometric_interpretation = fields.text("photometric_interpretation");
  if (out.photometric_interpretation != "MONOCHROME1" &&
      out.photometric_interpretation != "MONOCHROME2") {
    fields.fail("photometric_interpretation", R"(must be "MONOCHROME1" or "MONOCHROME2")");
  }
  out.bits_stored = fields.integer("bits_stored", 8, 16);
  out.pixel_signed = fields.flag("pixel_signed");
  out.rows = fields.integer("rows", 1, kDicomMaxSide);
  out.columns = fields.integer("columns", 1, kDicomMaxSide);
  out.rescale_slope = fields.number("rescale_slope");
  if (out.rescale_slope == 0.0) fields.fail("rescale_slope", "must not be 0");
  out.rescale_intercept = fields.number("rescale_intercept");
  out.sop_instance_uid_sha256 = fields.text("sop_instance_uid_sha256");
  if (!is_sha256_hex(out.sop_instance_uid_sha256)) {
    fields.fail("sop_instance_uid_sha256", "must be 64 lowercase hexadecimal digits");
  }

  Fields map(fields.required("value_map"), "value_map.", source);
  out.value_map.value_min = map.number("value_min");
  out.value_map.scale = map.positive("scale");
  out.value_map.inverted = map.flag("inverted");
  map.check_no_others();
  if (out.value_map.inverted != (out.photometric_interpretation == "MONOCHROME1")) {
    fields.fail("value_map", "'inverted' must be true exactly for MONOCHROME1");
  }

  Fields window(fields.required("window"), "window.", source);
  out.window.centre = window.number("centre");
  out.window.width = window.positive("width");
  const std::string window_source = window.text("source");
  if (window_source == "file") {
    out.window.source = DicomWindowSource::kFile;
  } else if (window_source == "percentiles") {
    out.window.source = DicomWindowSource::kPercentiles;
  } else {
    window.fail("source", R"(must be "file" or "percentiles")");
  }
  window.check_no_others();

  out.imager_pixel_spacing = fields.optional_spacing("imager_pixel_spacing_mm");
  out.pixel_spacing = fields.optional_spacing("pixel_spacing_mm");
  out.magnification_factor = fields.optional_positive("magnification_factor");
  out.distance_source_to_detector_mm = fields.optional_positive("distance_source_to_detector_mm");
  out.distance_source_to_patient_mm = fields.optional_positive("distance_source_to_patient_mm");
  out.view_position = fields.optional_text("view_position");
  if (const Json* orientation = fields.find("patient_orientation")) {
    if (!orientation->is_array() || orientation->size() != 2 || !(*orientation)[0].is_string() ||
        !(*orientation)[1].is_string() ||
        !is_orientation_letters((*orientation)[0].get<std::string>()) ||
        !is_orientation_letters((*orientation)[1].get<std::string>())) {
      fields.fail("patient_orientation",
                  R"(must be two directions made of A, P, R, L, H, F, e.g. ["L", "F"])");
    }
    out.patient_orientation = {(*orientation)[0].get<std::string>(),
                               (*orientation)[1].get<std::string>()};
  }
  out.image_laterality = fields.optional_text("image_laterality");
  if (out.image_laterality && *out.image_laterality != "R" && *out.image_laterality != "L" &&
      *out.image_laterality != "U" && *out.image_laterality != "B") {
    fields.fail("image_laterality", R"(must be "R", "L", "U" or "B")");
  }
  out.pixel_spacing_calibration_type = fields.optional_text("pixel_spacing_calibration_type");

  std::string png;
  try {
    png = base64_decode(fields.text("png_base64"), "field 'png_base64'");
  } catch (const InvalidInputError& error) {
    throw IoError(source, error.what());
  }
  if (fields.text("sha256") != hash::sha256_hex(png)) {
    fields.fail("sha256", "does not match the image in 'png_base64' (damaged or edited)");
  }
  fields.check_no_others();

  PngContent content = decode_png(source, png);
  auto* gray16 = std::get_if<GrayImage16>(&content.image);
  if (gray16 == nullptr) fields.fail("png_base64", "must hold a 16-bit grayscale PNG");
  if (gray16->width != out.columns || gray16->height != out.rows) {
    fields.fail("png_base64", "holds a " + std::to_string(gray16->width) + " x " +
                                  std::to_string(gray16->height) +
                                  " image; 'columns' x 'rows' say " + std::to_string(out.columns) +
                                  " x " + std::to_string(out.rows));
  }
  out.image = std::move(*gray16);
  return out;
}

}  // namespace mmm::image

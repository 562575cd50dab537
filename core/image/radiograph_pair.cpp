#include "core/image/radiograph_pair.h"

#include <nlohmann/json.hpp>
#include <utility>
#include <variant>

#include "core/base64.h"
#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/hash/sha256.h"
#include "core/image/file_bytes.h"
#include "core/image/png.h"

namespace mmm::image {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr const char* kFormat = "mmm-radiograph-pair";
constexpr int kVersion = 1;

std::string size_text(int width, int height) {
  return std::to_string(width) + " x " + std::to_string(height) + " pixels";
}

// Throws unless `png` decodes to a grayscale image of the view's size.
void check_image(const RadiographFile& file, const std::string& png, const fs::path& source) {
  const PngContent content = decode_png(source / file.image, png);
  int width = 0;
  int height = 0;
  if (const auto* gray16 = std::get_if<GrayImage16>(&content.image)) {
    width = gray16->width;
    height = gray16->height;
  } else if (const auto* gray8 = std::get_if<GrayImage8>(&content.image)) {
    width = gray8->width;
    height = gray8->height;
  } else {
    throw IoError(source / file.image,
                  "holds colour, a radiograph must be grayscale (convert it first)");
  }
  if (width != file.view.width || height != file.view.height) {
    throw IoError(source / file.image,
                  file.image + " is " + size_text(width, height) + ", the calibration of view '" +
                      file.view.name + "' says " + size_text(file.view.width, file.view.height));
  }
}

}  // namespace

const RadiographFile& RadiographPair::view(const std::string& name) const {
  std::string known;
  for (const RadiographFile& file : views) {
    if (file.view.name == name) return file;
    known += (known.empty() ? "" : ", ") + file.view.name;
  }
  throw InvalidInputError("the radiographs have no view '" + name + "' (views: " + known + ")");
}

std::vector<RadiographView> RadiographPair::calibrated_views() const {
  std::vector<RadiographView> out;
  out.reserve(views.size());
  for (const RadiographFile& file : views) out.push_back(file.view);
  return out;
}

std::string RadiographPair::image_sha256(const std::string& name) const {
  return hash::sha256_hex(images.at(view(name).image));
}

GrayImage16 RadiographPair::image(const std::string& name) const {
  const RadiographFile& file = view(name);
  PngContent content = decode_png(file.image, images.at(file.image));
  if (auto* gray16 = std::get_if<GrayImage16>(&content.image)) return std::move(*gray16);
  const auto& gray8 = std::get<GrayImage8>(content.image);
  GrayImage16 wide(gray8.width, gray8.height);
  for (std::size_t i = 0; i < wide.pixels.size(); ++i) {
    wide.pixels[i] = static_cast<std::uint16_t>(gray8.pixels[i] * 257U);
  }
  return wide;
}

RadiographPair load_radiograph_pair(const fs::path& sidecar) {
  RadiographPair pair;
  pair.views = read_view_sidecar(sidecar);
  const fs::path folder = sidecar.parent_path();
  for (const RadiographFile& file : pair.views) {
    std::string png =
        detail::read_file_bytes(folder / file.image, "a radiograph (PNG)", kPngMaxFileBytes);
    check_image(file, png, folder);
    pair.images.emplace(file.image, std::move(png));
  }
  return pair;
}

RadiographPair make_radiograph_pair(std::vector<RadiographFile> views,
                                    const std::map<std::string, std::string>& png_by_view,
                                    const fs::path& source) {
  RadiographPair pair;
  for (RadiographFile& file : views) {
    const auto it = png_by_view.find(file.view.name);
    if (it == png_by_view.end()) {
      throw InvalidInputError("no image was given for view '" + file.view.name +
                              "' of the calibration " + source.string());
    }
    file.image = file.view.name + ".png";
    check_image(file, it->second, source);
    pair.images.emplace(file.image, it->second);
  }
  pair.views = std::move(views);
  return pair;
}

std::string radiograph_pair_to_json_text(const RadiographPair& pair) {
  Json root;
  root["format"] = kFormat;
  root["version"] = kVersion;
  root["calibration"] = parse_json(view_sidecar_text(pair.views));
  Json images = Json::object();
  for (const RadiographFile& file : pair.views) {
    const std::string& png = pair.images.at(file.image);
    images[file.image] = {{"sha256", hash::sha256_hex(png)}, {"png_base64", base64_encode(png)}};
    const auto origin = pair.origins.find(file.image);
    if (origin != pair.origins.end()) {
      images[file.image]["window"] = {origin->second.window_centre, origin->second.window_width};
      images[file.image]["sop_instance_uid_sha256"] = origin->second.sop_instance_uid_sha256;
    }
  }
  root["images"] = std::move(images);
  return root.dump();
}

RadiographPair radiograph_pair_from_json_text(const std::string& text, const fs::path& source) {
  Json root;
  try {
    root = parse_json(text);
  } catch (const Json::parse_error& error) {
    throw IoError(source, std::string("is not a radiograph pair (JSON): ") + error.what());
  }
  if (!root.is_object() || root.value("format", "") != kFormat) {
    throw IoError(source, std::string("field 'format' must be \"") + kFormat + "\"");
  }
  if (root.value("version", 0) != kVersion) {
    throw IoError(source, "field 'version' must be " + std::to_string(kVersion));
  }
  if (!root.contains("calibration") || !root.contains("images") || !root["images"].is_object()) {
    throw IoError(source, "fields 'calibration' and 'images' (an object) are required");
  }
  RadiographPair pair;
  pair.views = parse_view_sidecar(root["calibration"].dump(), source);
  const Json& images = root["images"];
  for (const RadiographFile& file : pair.views) {
    const std::string where = "images['" + file.image + "']";
    const auto it = images.find(file.image);
    if (it == images.end() || !it->is_object() || !it->contains("png_base64") ||
        !(*it)["png_base64"].is_string()) {
      throw IoError(source, where + ": missing, or without a 'png_base64' string");
    }
    std::string png;
    try {
      png = base64_decode((*it)["png_base64"].get<std::string>(), where);
    } catch (const InvalidInputError& error) {
      throw IoError(source, error.what());
    }
    const std::string expected = it->value("sha256", "");
    if (hash::sha256_hex(png) != expected) {
      throw IoError(source, where + ": the image's SHA-256 is not the one recorded (damaged)");
    }
    check_image(file, png, source);
    pair.images.emplace(file.image, std::move(png));
    if (it->contains("window")) {
      const Json& window = (*it)["window"];
      const Json& uid = it->value("sop_instance_uid_sha256", Json());
      if (!window.is_array() || window.size() != 2 || !window[0].is_number() ||
          !window[1].is_number() || !(window[1].get<double>() > 0) || !uid.is_string() ||
          uid.get<std::string>().size() != 64) {
        throw IoError(source, where +
                                  ": 'window' must be [centre, width > 0] beside a 64-digit "
                                  "'sop_instance_uid_sha256'");
      }
      pair.origins[file.image] = {window[0].get<double>(), window[1].get<double>(),
                                  uid.get<std::string>()};
    }
  }
  return pair;
}

}  // namespace mmm::image

#include "nodes/load_radiographs.h"

#include <array>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/image/deidentified_radiograph.h"
#include "core/image/dicom_radiograph.h"
#include "core/image/dicom_series.h"
#include "core/image/dicom_views.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"

namespace mmm::nodes {
namespace {

constexpr std::string_view kDeidentifiedFormat = "mmm-deidentified-radiograph";

// One view's image as given: PNG bytes, or a DICOM radiograph (de-identified
// by the study, or a DICOM file met outside a study).
struct GivenImage {
  std::string png;
  std::optional<image::DicomRadiograph> dicom;
};

// `view` names the view the image is given for: a series (a folder of DICOM
// files, de-identified by the study) gives the image of that view.
GivenImage read_image(const std::string& bytes, const std::filesystem::path& source,
                      const std::string& view, workflow::NodeContext& context) {
  if (image::looks_like_dicom(bytes)) return {{}, image::read_dicom_radiograph(bytes, source)};
  if (image::is_deidentified_series(bytes)) {
    std::vector<image::DicomRadiograph> series =
        image::deidentified_series_from_text(bytes, source);
    const image::SeriesChoice choice = image::choose_view_image(series, view, source);
    context.info("view '" + view + "' from a DICOM folder: " + choice.reason);
    return {{}, std::move(series[choice.index])};
  }
  if (bytes.find(kDeidentifiedFormat) != std::string::npos && !bytes.empty() && bytes[0] == '{') {
    return {{}, image::deidentified_radiograph_from_text(bytes, source)};
  }
  return {bytes, std::nullopt};
}

}  // namespace

workflow::NodeSpec LoadRadiographs::spec() {
  using workflow::port::File;
  using workflow::port::RadiographPair;
  return workflow::NodeSpec{"load_radiographs", 2,
                            "A calibrated frontal + lateral radiograph pair: PNG or DICOM images, "
                            "calibrated by a sidecar or by the DICOM geometry attributes"}
      .optional_input<File>(
          "calibration",
          "View sidecar (views.json): projection matrices, sizes, spacing; without "
          "it the geometry comes from the DICOM attributes")
      .input<File>("frontal",
                   "Frontal radiograph: grayscale PNG or DICOM (DX, CR, SC), or a folder of "
                   "DICOM files holding it (View Position AP or PA)")
      .input<File>("lateral",
                   "Lateral radiograph: grayscale PNG or DICOM, or a folder of DICOM files "
                   "holding it (View Position LL or RL)")
      .param_enum("model", "pinhole", {"pinhole", "slot-scanning"},
                  "Projection model when the calibration comes from DICOM attributes: two "
                  "conventional radiographs, or an EOS-type slot scan")
      .output<RadiographPair>("radiographs", "The views with their images");
}

void LoadRadiographs::run(workflow::NodeContext& context) {
  std::map<std::string, GivenImage> given;
  for (const char* name : {"frontal", "lateral"}) {
    given.emplace(name,
                  read_image(context.input_bytes(name), context.input(name).path, name, context));
  }
  std::vector<image::RadiographFile> views;
  std::filesystem::path source;
  std::array<bool, 2> mirrored = {false, false};
  if (context.has_input("calibration")) {
    source = context.input("calibration").path;
    views = image::parse_view_sidecar(context.input_bytes("calibration"), source);
  } else {
    const GivenImage& frontal = given.at("frontal");
    const GivenImage& lateral = given.at("lateral");
    if (!frontal.dicom || !lateral.dicom) {
      throw IoError(context.input(!frontal.dicom ? "frontal" : "lateral").path,
                    "is not DICOM, and no calibration was given; hint: connect the "
                    "'calibration' input (views.json) for PNG radiographs");
    }
    const image::DicomPairGeometry geometry =
        image::views_from_dicom({&*frontal.dicom, context.input("frontal").path},
                                {&*lateral.dicom, context.input("lateral").path},
                                *image::projection_model_from_name(context.text("model")));
    mirrored = geometry.mirrored;
    for (const image::RadiographView& view : geometry.views) views.push_back({view, ""});
    source = context.input("frontal").path;
    context.info("calibrated from the DICOM attributes (" + context.text("model") + " model)");
  }
  std::map<std::string, std::string> png_by_view;
  std::map<std::string, image::ImageOrigin> origins;
  for (std::size_t k = 0; k < views.size(); ++k) {
    const std::string& name = views[k].view.name;
    const auto it = given.find(name);
    if (it == given.end()) continue;  // make_radiograph_pair names the missing view
    if (!it->second.dicom) {
      png_by_view[name] = it->second.png;
      continue;
    }
    const image::DicomRadiograph& dicom = *it->second.dicom;
    const bool flip = k < mirrored.size() && mirrored[k];
    png_by_view[name] = image::encode_png(flip ? image::mirror_columns(dicom.image) : dicom.image);
    origins[name] = {dicom.window.centre, dicom.window.width, dicom.sop_instance_uid_sha256};
    if (flip) context.info("view '" + name + "': mirrored to be seen from the source");
  }
  image::RadiographPair pair = image::make_radiograph_pair(std::move(views), png_by_view, source);
  for (const auto& [name, origin] : origins) pair.origins[name + ".png"] = origin;
  for (const image::RadiographFile& file : pair.views) {
    context.info("view '" + file.view.name + "' (" + image::projection_model_name(file.view.model) +
                 "): " + std::to_string(file.view.width) + " x " +
                 std::to_string(file.view.height) + " pixels, " +
                 std::to_string(file.view.pixel_spacing_mm) + " mm/pixel");
  }
  context.set_output("radiographs", image::radiograph_pair_to_json_text(pair));
}

}  // namespace mmm::nodes

#include "nodes/load_radiographs.h"

#include <map>
#include <string>

#include "core/image/radiograph_pair.h"

namespace mmm::nodes {

workflow::NodeSpec LoadRadiographs::spec() {
  using workflow::port::File;
  using workflow::port::RadiographPair;
  return workflow::NodeSpec{"load_radiographs", 1,
                            "A calibrated frontal + lateral radiograph pair from its calibration "
                            "sidecar and two PNG images"}
      .input<File>("calibration", "View sidecar (views.json): projection matrices, sizes, spacing")
      .input<File>("frontal", "Frontal radiograph, grayscale PNG")
      .input<File>("lateral", "Lateral radiograph, grayscale PNG")
      .output<RadiographPair>("radiographs", "The views with their images");
}

void LoadRadiographs::run(workflow::NodeContext& context) {
  const auto& calibration = context.input("calibration");
  std::vector<image::RadiographFile> views =
      image::parse_view_sidecar(context.input_bytes("calibration"), calibration.path);
  const std::map<std::string, std::string> images = {{"frontal", context.input_bytes("frontal")},
                                                     {"lateral", context.input_bytes("lateral")}};
  const image::RadiographPair pair =
      image::make_radiograph_pair(std::move(views), images, calibration.path.parent_path());
  for (const image::RadiographFile& file : pair.views) {
    context.info("view '" + file.view.name + "': " + std::to_string(file.view.width) + " x " +
                 std::to_string(file.view.height) + " pixels, " +
                 std::to_string(file.view.pixel_spacing_mm) + " mm/pixel");
  }
  context.set_output("radiographs", image::radiograph_pair_to_json_text(pair));
}

}  // namespace mmm::nodes

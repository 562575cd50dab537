// An operator's landmark submission (the JSON of `mmm task submit --file` and
// of the web API), evaluated against a task over a synthetic calibrated pair.
#include <exception>

#include "core/bounded_json.h"
#include "core/image/projection.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"
#include "worklists/landmark_task.h"

namespace {

mmm::worklists::Task make_task() {
  mmm::image::BiplanarOptions options;
  options.isocentre_mm = {0, 0, 500};
  options.detector_pixel_pitch_mm = 4.0;
  nlohmann::json views = nlohmann::json::array();
  for (const mmm::image::RadiographView& view : mmm::image::make_biplanar_views(options)) {
    nlohmann::json P = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) {
      P.push_back({view.P(r, 0), view.P(r, 1), view.P(r, 2), view.P(r, 3)});
    }
    views.push_back({{"name", view.name},
                     {"width", view.width},
                     {"height", view.height},
                     {"pixel_spacing_mm", view.pixel_spacing_mm},
                     {"P", P}});
  }
  mmm::worklists::Task task;
  task.id = "0123456789";
  task.node = "landmarks";
  task.node_type = mmm::worklists::kLandmarkStationType;
  task.request = {{"kind", "landmarks"},
                  {"landmarks",
                   {{{"name", "femoral_head_centre_r"}, {"required", true}},
                    {{"name", "patella_centre_r"}, {"required", true}},
                    {{"name", "ankle_centre_r"}, {"required", false}}}},
                  {"views", views},
                  {"reprojection_tolerance_mm", 3.0},
                  {"side", "right"},
                  {"review", false}};
  return task;
}

}  // namespace

namespace mmm::fuzz {

void submission(const std::uint8_t* data, std::size_t size) {
  static const worklists::Task task = make_task();
  try {
    const nlohmann::json submission = parse_json(as_text(data, size));
    (void)worklists::evaluate_landmark_submission(task, submission);
  } catch (const std::exception&) {
  }
}

}  // namespace mmm::fuzz

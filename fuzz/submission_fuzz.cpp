// An operator's submission (the JSON of `mmm task submit --file` and of the
// web API), evaluated the way the task actions do, through the task
// behaviour every manual node type of mmm registers (workflow/manual_task.h),
// against a task request over a synthetic calibrated pair: the landmark
// station's and the outline review's, each input against both.
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "core/bounded_json.h"
#include "core/image/projection.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"
#include "nodes/registry.h"

namespace {

using Json = nlohmann::json;

Json synthetic_views() {
  mmm::image::BiplanarOptions options;
  options.isocentre_mm = {0, 0, 500};
  options.detector_pixel_pitch_mm = 4.0;
  Json views = Json::array();
  for (const mmm::image::RadiographView& view : mmm::image::make_biplanar_views(options)) {
    Json P = Json::array();
    for (int r = 0; r < 3; ++r) {
      P.push_back({view.P(r, 0), view.P(r, 1), view.P(r, 2), view.P(r, 3)});
    }
    views.push_back({{"name", view.name},
                     {"width", view.width},
                     {"height", view.height},
                     {"pixel_spacing_mm", view.pixel_spacing_mm},
                     {"P", P}});
  }
  return views;
}

// A request of each kind of task, as its node type's behaviour builds it.
Json request_of_kind(const std::string& kind, const Json& views) {
  if (kind == "landmarks") {
    return {{"kind", "landmarks"},
            {"landmarks",
             {{{"name", "femoral_head_centre_r"}, {"required", true}},
              {{"name", "patella_centre_r"}, {"required", true}},
              {{"name", "ankle_centre_r"}, {"required", false}}}},
            {"views", views},
            {"reprojection_tolerance_mm", 3.0},
            {"side", "right"},
            {"review", false}};
  }
  const Json outline = {{{10.0, 10.0}, {20.0, 30.0}, {10.0, 10.0}}};
  return {{"kind", kind},
          {"views", views},
          {"bones",
           {{{"name", "femur_r"}, {"outlines", {{"frontal", outline}, {"lateral", outline}}}},
            {{"name", "tibia_r"}, {"outlines", {{"frontal", outline}, {"lateral", outline}}}}}},
          {"radiographs", std::string(64, 'a')},
          {"atlas", std::string(64, 'b')},
          {"review", false}};
}

struct Evaluator {
  mmm::workflow::SubmissionFunction evaluate;
  Json request;
};

std::vector<Evaluator> make_evaluators() {
  static const mmm::workflow::NodeRegistry registry = mmm::nodes::make_node_registry();
  const Json views = synthetic_views();
  std::vector<Evaluator> evaluators;
  for (const mmm::workflow::NodeType* type : registry.all()) {
    if (!type->spec.is_manual()) continue;
    evaluators.push_back({type->task.evaluate, request_of_kind(type->task.kind, views)});
  }
  return evaluators;
}

}  // namespace

namespace mmm::fuzz {

void submission(const std::uint8_t* data, std::size_t size) {
  static const std::vector<Evaluator> evaluators = make_evaluators();
  for (const Evaluator& evaluator : evaluators) {
    try {
      const Json submission = parse_json(as_text(data, size));
      (void)evaluator.evaluate(evaluator.request, submission);
    } catch (const std::exception&) {
    }
  }
}

}  // namespace mmm::fuzz

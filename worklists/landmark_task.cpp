#include "worklists/landmark_task.h"

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/image/radiograph_pair.h"
#include "core/landmarks/landmark_labels.h"
#include "core/landmarks/landmark_set.h"
#include "core/landmarks/landmark_validation.h"
#include "worklists/task_views.h"

namespace mmm::worklists {
namespace {

using Json = nlohmann::json;

struct LandmarkText {
  const char* stem;  // name without the side suffix
  const char* label;
  const char* hint;
};

constexpr std::array<LandmarkText, 3> kLandmarks = {{
    {"femoral_head_centre", "Femoral head centre",
     "the centre of the circle that best fits the femoral head's outline, in both views"},
    {"patella_centre", "Patella centre",
     "the centre of the patella's outline: frontal, the oval over the distal femur; lateral, "
     "the middle of the patella in front of the femoral condyles"},
    {"ankle_centre", "Ankle centre",
     "frontal: midway between the tips of the medial and lateral malleoli; lateral: the centre "
     "of the talar dome's arc"},
}};

// The pelvis's landmarks (param pelvis_landmarks): both anterior superior
// iliac spines, whatever the leg. With them the pelvis's width and size are
// measured rather than guessed from the leg (bench/run scaling: the mean
// bone surface error of a scaled atlas drops from ~2.2 mm to ~0.9 mm).
constexpr std::array<LandmarkText, 2> kPelvisLandmarks = {{
    {"asis_r", "Right ASIS",
     "anterior superior iliac spine: frontal, the anterior tip of the iliac crest where the "
     "wing's outline turns down (lateral of the hip); lateral, the most anterior point of the "
     "ilium above the hip"},
    {"asis_l", "Left ASIS", "as the right ASIS, on the other side of the pelvis"},
}};

constexpr const char* kDefaultInstructions =
    "Place each landmark in the frontal view and in the lateral view. The horizontal guide line "
    "in one view shows the height of the point placed in the other: the same landmark lies on "
    "it. Use window/level to see the bone outlines. The reprojection error shows how well the "
    "two clicks agree; submit when every landmark is placed.";

std::string suffix(const std::string& side) { return side == "left" ? "_l" : "_r"; }

const workflow::ParamValue& param(const workflow::CacheKeyParts& parts, const char* name) {
  return key_param(parts, name, "landmark task");
}

landmarks::ValidationRules rules_of(const Json& request) {
  landmarks::ValidationRules rules;
  const std::string side = request.at("side").get<std::string>();
  const std::string s = suffix(side);
  rules.side = side;
  rules.required.clear();
  rules.optional.clear();
  for (const Json& landmark : request.at("landmarks")) {
    (landmark.at("required").get<bool>() ? rules.required : rules.optional)
        .push_back(landmark.at("name").get<std::string>());
  }
  rules.top_to_bottom = {"femoral_head_centre" + s, "patella_centre" + s, "ankle_centre" + s};
  const bool pelvis = std::ranges::any_of(request.at("landmarks"), [](const Json& landmark) {
    return landmark.at("name").get<std::string>() == "asis_l";
  });
  if (pelvis) {
    // The ASIS of the leg's side above its femoral head; the other ASIS on
    // the other side; adult inter-ASIS distances 190-290 mm, widened.
    rules.top_to_bottom.insert(rules.top_to_bottom.begin(), side == "left" ? "asis_l" : "asis_r");
    rules.opposite_side = {side == "left" ? "asis_r" : "asis_l"};
  }
  for (landmarks::DistanceRange& range : rules.distances) {
    range.from.replace(range.from.size() - 2, 2, s);
    range.to.replace(range.to.size() - 2, 2, s);
  }
  if (pelvis) rules.distances.push_back({"asis_r", "asis_l", 160.0, 340.0});
  rules.reprojection_tolerance_mm = request.at("reprojection_tolerance_mm").get<double>();
  return rules;
}

// The submission's pixels; every malformed part becomes a reason.
landmarks::PixelSubmission parse_submission(const Json& submission,
                                            std::vector<std::string>& reasons) {
  landmarks::PixelSubmission pixels;
  if (!submission.is_object() || !submission.contains("landmarks") ||
      !submission["landmarks"].is_object()) {
    reasons.emplace_back(
        "the submission must be an object {\"landmarks\": {NAME: {VIEW: [u, v]}}}");
    return pixels;
  }
  for (const auto& [name, views] : submission["landmarks"].items()) {
    if (!views.is_object()) {
      reasons.push_back("landmark '" + name + "': expected {VIEW: [u, v], ...}");
      continue;
    }
    pixels[name];  // named, even without a view: validation reports what is missing
    for (const auto& [view, uv] : views.items()) {
      if (!uv.is_array() || uv.size() != 2 || !uv[0].is_number() || !uv[1].is_number()) {
        std::string reason = "landmark '" + name;
        reason += "' in view '" + view + "': the position must be [u, v], two numbers (pixels)";
        reasons.push_back(std::move(reason));
        continue;
      }
      pixels[name][view] = {uv[0].get<double>(), uv[1].get<double>()};
    }
  }
  return pixels;
}

}  // namespace

workflow::NodeSpec LandmarkStation::spec() {
  using workflow::port::LandmarkSet;
  using workflow::port::RadiographPair;
  return workflow::NodeSpec{"landmark_station", 1,
                            "Operator places the femoral-head, patella and ankle centres on the "
                            "two radiographs; mmm triangulates and checks them"}
      .manual()
      .input<RadiographPair>("radiographs", "The patient's calibrated frontal and lateral views")
      .optional_input<workflow::port::String>("patient",
                                              "Patient identifier, shown to the operator")
      .param<bool>("require_ankle", false,
                   "The ankle centre is required (else optional: scaling uses it when given)")
      .param<bool>("pelvis_landmarks", false,
                   "Also ask for both anterior superior iliac spines (ASIS): scaling then "
                   "measures the pelvis instead of inferring it from the leg")
      .param<double>("reprojection_tolerance_mm", 3.0,
                     "Largest reprojection error accepted in any view (two clicks that disagree "
                     "by more are rejected)",
                     {.min = 0.1, .max = 50}, "mm")
      .param_enum("side", "right", {"right", "left"}, "The leg whose landmarks are placed")
      .param<bool>("review", false,
                   "A second operator must accept each submission (four-eyes principle)")
      .param<std::string>("instructions", kDefaultInstructions, "Shown to the operator")
      .output<LandmarkSet>("landmarks", "Triangulated landmarks, patient frame (mm)");
}

void LandmarkStation::run(workflow::NodeContext& /*context*/) {
  throw InvalidInputError(
      "landmark_station is a manual node: its result comes from an operator; hint: 'mmm "
      "worklist' lists its task, 'mmm task submit' or 'mmm serve' provide the landmarks");
}

workflow::ManualTaskBehaviour LandmarkStation::task_behaviour() {
  workflow::ManualTaskBehaviour task;
  task.kind = "landmarks";
  task.request = landmark_task_request;
  task.evaluate = evaluate_landmark_submission;
  task.submission_fields = {"landmarks"};
  return task;
}

Json landmark_task_request(const workflow::CacheKeyParts& parts,
                           const workflow::ArtifactStore& artifacts) {
  const auto input = parts.input_hashes.find("radiographs");
  if (input == parts.input_hashes.end()) {
    throw InvalidInputError("landmark task: the node has no 'radiographs' input");
  }
  const image::RadiographPair pair = image::radiograph_pair_from_json_text(
      artifacts.get(input->second), artifacts.path_of(input->second));
  const std::string side = std::get<std::string>(param(parts, "side"));
  const bool require_ankle = std::get<bool>(param(parts, "require_ankle"));
  Json request;
  request["kind"] = "landmarks";
  request["instructions"] = std::get<std::string>(param(parts, "instructions"));
  request["side"] = side;
  request["review"] = std::get<bool>(param(parts, "review"));
  request["reprojection_tolerance_mm"] =
      std::get<double>(param(parts, "reprojection_tolerance_mm"));
  request["radiographs"] = input->second;
  request["patient"] = optional_text_input(parts, artifacts, "patient");
  Json landmarks = Json::array();
  for (const LandmarkText& text : kLandmarks) {
    const std::string stem = text.stem;
    landmarks.push_back({{"name", stem + suffix(side)},
                         {"label", std::string(text.label) + " (" + side + ")"},
                         {"required", stem != "ankle_centre" || require_ankle},
                         {"hint", text.hint},
                         {"definition", landmarks::landmark_definition(stem + suffix(side))}});
  }
  // Absent from the keys of tasks opened before the parameter existed.
  const auto pelvis = parts.params.find("pelvis_landmarks");
  if (pelvis != parts.params.end() && std::get<bool>(pelvis->second)) {
    for (const LandmarkText& text : kPelvisLandmarks) {
      landmarks.push_back({{"name", text.stem},
                           {"label", text.label},
                           {"required", true},
                           {"hint", text.hint},
                           {"definition", landmarks::landmark_definition(text.stem)}});
    }
  }
  request["landmarks"] = landmarks;
  RequestViews views = request_views(pair);
  request["views"] = std::move(views.views);
  request["images"] = std::move(views.images);
  return request;
}

ManualEvaluation evaluate_landmark_submission(const Json& request, const Json& submission) {
  ManualEvaluation evaluation;
  const landmarks::PixelSubmission pixels = parse_submission(submission, evaluation.reasons);
  const std::vector<image::RadiographView> views = views_of_request(request);
  const landmarks::ValidationResult result =
      landmarks::validate_submission(views, pixels, rules_of(request));
  evaluation.reasons.insert(evaluation.reasons.end(), result.reasons.begin(), result.reasons.end());
  evaluation.values = Json::object();
  if (result.landmarks) evaluation.values = Json(*result.landmarks);
  if (evaluation.reasons.empty() && result.landmarks) {
    evaluation.outputs["landmarks"] = {workflow::PortType::kLandmarkSet,
                                       landmarks::landmark_set_to_json_text(*result.landmarks)};
  }
  return evaluation;
}

}  // namespace mmm::worklists

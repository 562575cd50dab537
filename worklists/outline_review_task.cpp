#include "worklists/outline_review_task.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/image/outline_corrections.h"
#include "core/image/outline_overlay.h"
#include "core/image/radiograph_pair.h"
#include "core/image/silhouette.h"
#include "core/mesh/io/mesh_io.h"
#include "worklists/task_views.h"

namespace mmm::worklists {
namespace {

using Json = nlohmann::json;

constexpr const char* kReviewWhat = "outline review task";

constexpr const char* kReviewInstructions =
    "Check each bone's outline against the radiographs in both views. If every outline follows "
    "its bone's edge, accept. Otherwise click on the true edge near a misplaced outline (the "
    "nearest outline picks the bone; points go to that bone in that view), then submit the "
    "corrections. Use window/level to see the bone edges.";

// Outline points are rounded to this (pixels): far below what an operator
// can see, and the request stays small.
constexpr double kOutlineResolutionPx = 0.1;

// A folder under the system's temporary folder, removed with its content.
class UnpackedFolder {
 public:
  UnpackedFolder() {
    static std::atomic<unsigned> counter{0};
    const auto ticks = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = std::filesystem::temp_directory_path() /
            ("mmm-outline-review-" + std::to_string(::getpid()) + "-" + std::to_string(ticks) +
             "-" + std::to_string(counter++));
  }
  ~UnpackedFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  UnpackedFolder(const UnpackedFolder&) = delete;
  UnpackedFolder& operator=(const UnpackedFolder&) = delete;
  UnpackedFolder(UnpackedFolder&&) = delete;
  UnpackedFolder& operator=(UnpackedFolder&&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

const std::string& input_hash(const workflow::CacheKeyParts& parts, const char* port) {
  const auto input = parts.input_hashes.find(port);
  if (input == parts.input_hashes.end()) {
    throw InvalidInputError(std::string(kReviewWhat) + ": the node has no '" + port + "' input");
  }
  return input->second;
}

std::string colour_text(image::Rgb8 colour) {
  std::array<char, 8> text{};
  std::snprintf(text.data(), text.size(), "#%02x%02x%02x", colour.r, colour.g, colour.b);
  return text.data();
}

// Divided, not multiplied, by the step count: the nearest double to the
// rounded value, printed short ("412.3", not "412.30000000000001").
double rounded_px(double value) {
  constexpr double kSteps = 1.0 / kOutlineResolutionPx;
  return std::round(value * kSteps) / kSteps;
}

// Every bone's outline in every view, with its colour.
Json bone_outlines(const image::RadiographPair& pair, const std::string& atlas_bundle,
                   const std::string& level) {
  const UnpackedFolder folder;
  unpack_directory(atlas_bundle, folder.path(), "input 'atlas'");
  const atlas::Atlas atlas = atlas::read_atlas(folder.path());
  const std::vector<image::Rgb8> colours =
      image::distinct_colours(static_cast<int>(atlas.bones.size()));
  Json bones = Json::array();
  for (std::size_t b = 0; b < atlas.bones.size(); ++b) {
    const atlas::Bone& bone = atlas.bones[b];
    const atlas::MeshLevel* found = nullptr;
    std::string levels;
    for (const atlas::MeshLevel& mesh_level : bone.meshes) {
      if (mesh_level.level == level) found = &mesh_level;
      levels += (levels.empty() ? "" : ", ") + mesh_level.level;
    }
    if (found == nullptr) {
      std::string message = std::string(kReviewWhat) + ": bone '" + bone.name;
      message += "' of the atlas has no mesh level '" + level;
      message += "'; hint: set the node's parameter 'level' to one of " + levels;
      throw InvalidInputError(message);
    }
    const mesh::IndexedMesh surface = mesh::read_mesh(folder.path() / found->file);
    Json outlines = Json::object();
    for (const image::RadiographFile& file : pair.views) {
      Json polylines = Json::array();
      for (const image::Polyline2d& polyline : image::silhouette_polylines(surface, file.view)) {
        Json points = Json::array();
        for (const Eigen::Vector2d& p : polyline) {
          points.push_back({rounded_px(p.x()), rounded_px(p.y())});
        }
        polylines.push_back(std::move(points));
      }
      outlines[file.view.name] = std::move(polylines);
    }
    bones.push_back(
        {{"name", bone.name}, {"colour", colour_text(colours[b])}, {"outlines", outlines}});
  }
  return bones;
}

std::string names_text(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

// What the request offers to correct: bone names and view sizes.
struct ReviewTargets {
  std::vector<std::string> bones;
  std::vector<std::string> views;
  std::map<std::string, std::pair<int, int>> sizes;  // view -> width, height (pixels)
};

ReviewTargets targets_of(const Json& request) {
  ReviewTargets targets;
  for (const Json& bone : request.at("bones")) {
    targets.bones.push_back(bone.at("name").get<std::string>());
  }
  for (const Json& view : request.at("views")) {
    const std::string name = view.at("name").get<std::string>();
    targets.views.push_back(name);
    targets.sizes[name] = {view.at("width").get<int>(), view.at("height").get<int>()};
  }
  return targets;
}

bool is_known(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// One correction of the submission; nullopt (and reasons) when malformed.
std::optional<image::OutlineCorrection> read_correction(const Json& entry, std::size_t index,
                                                        const ReviewTargets& targets,
                                                        std::vector<std::string>& reasons) {
  const std::string where = "corrections[" + std::to_string(index) + "]";
  if (!entry.is_object()) {
    reasons.push_back(where + R"(: expected {"bone", "view", "points": [[u, v], ...]})");
    return std::nullopt;
  }
  const std::size_t before = reasons.size();
  for (const auto& [key, value] : entry.items()) {
    if (key != "bone" && key != "view" && key != "points") {
      std::string reason = where + ": unknown field '";
      reason += key + "'; the fields are bone, view, points";
      reasons.push_back(std::move(reason));
    }
  }
  image::OutlineCorrection correction;
  const Json bone = entry.value("bone", Json());
  if (!bone.is_string() || !is_known(targets.bones, bone.get<std::string>())) {
    reasons.push_back(where + ": 'bone' must be one of the atlas's bones (" +
                      names_text(targets.bones) + "), got " + bone.dump());
  } else {
    correction.bone = bone.get<std::string>();
  }
  const Json view = entry.value("view", Json());
  if (!view.is_string() || !is_known(targets.views, view.get<std::string>())) {
    reasons.push_back(where + ": 'view' must be one of the views (" + names_text(targets.views) +
                      "), got " + view.dump());
  } else {
    correction.view = view.get<std::string>();
  }
  const Json points = entry.value("points", Json());
  if (!points.is_array() || points.empty()) {
    reasons.push_back(where + ": 'points' must be a non-empty list of [u, v] pixel positions");
  } else if (points.size() > image::kMaxPointsPerCorrection) {
    reasons.push_back(where + ": " + std::to_string(points.size()) + " points, at most " +
                      std::to_string(image::kMaxPointsPerCorrection) +
                      " per bone and view are allowed");
  } else {
    for (std::size_t k = 0; k < points.size(); ++k) {
      const Json& uv = points[k];
      const std::string at = where + ".points[" + std::to_string(k) + "]";
      if (!uv.is_array() || uv.size() != 2 || !uv[0].is_number() || !uv[1].is_number()) {
        reasons.push_back(at + ": must be [u, v], two numbers (pixels)");
        continue;
      }
      const Eigen::Vector2d p(uv[0].get<double>(), uv[1].get<double>());
      if (!p.allFinite()) {
        reasons.push_back(at + ": must be finite");
        continue;
      }
      if (!correction.view.empty()) {
        const auto [width, height] = targets.sizes.at(correction.view);
        if (p.x() < 0 || p.y() < 0 || p.x() > width || p.y() > height) {
          reasons.push_back(at + ": (" + uv[0].dump() + ", " + uv[1].dump() +
                            ") lies outside view '" + correction.view + "' (0-" +
                            std::to_string(width) + " x 0-" + std::to_string(height) + " pixels)");
          continue;
        }
      }
      correction.points_px.push_back(p);
    }
  }
  if (reasons.size() != before) return std::nullopt;
  return correction;
}

}  // namespace

workflow::NodeSpec OutlineReviewStation::spec() {
  return workflow::NodeSpec{"outline_review", 1,
                            "Operator checks the atlas bones' outlines projected onto the two "
                            "radiographs: accepts them, or marks where the true edges lie"}
      .manual()
      .input<workflow::port::RadiographPair>("radiographs",
                                             "The patient's calibrated frontal and lateral views")
      .input<workflow::port::Atlas>("atlas",
                                    "The bones fitted to the radiographs (their outlines are "
                                    "shown), e.g. by fit_bone_outlines")
      .optional_input<workflow::port::String>("patient",
                                              "Patient identifier, shown to the operator")
      .param<bool>("review", false,
                   "A second operator must accept each submission (four-eyes principle)")
      .param<std::string>("instructions", kReviewInstructions, "Shown to the operator")
      .param<std::string>("level", "lod1",
                          "The atlas mesh level whose outlines are shown (a coarse level keeps "
                          "the outlines light; every bone must have it)")
      .output<workflow::port::OutlineCorrections>(
          "corrections",
          "The verdict: accepted as they are, or edge points per bone and view (pixels)");
}

void OutlineReviewStation::run(workflow::NodeContext& /*context*/) {
  throw InvalidInputError(
      "outline_review is a manual node: its result comes from an operator; hint: 'mmm "
      "worklist' lists its task, 'mmm task submit' or 'mmm serve' provide the verdict");
}

workflow::ManualTaskBehaviour OutlineReviewStation::task_behaviour() {
  workflow::ManualTaskBehaviour task;
  task.kind = "outline_review";
  task.request = outline_review_request;
  task.evaluate = evaluate_outline_review;
  task.submission_fields = {"decision", "corrections"};
  return task;
}

Json outline_review_request(const workflow::CacheKeyParts& parts,
                            const workflow::ArtifactStore& artifacts) {
  const std::string& pair_hash = input_hash(parts, "radiographs");
  const std::string& atlas_hash = input_hash(parts, "atlas");
  const image::RadiographPair pair =
      image::radiograph_pair_from_json_text(artifacts.get(pair_hash), artifacts.path_of(pair_hash));
  const std::string level = std::get<std::string>(key_param(parts, "level", kReviewWhat));
  Json request;
  request["kind"] = "outline_review";
  request["instructions"] = std::get<std::string>(key_param(parts, "instructions", kReviewWhat));
  request["review"] = std::get<bool>(key_param(parts, "review", kReviewWhat));
  request["level"] = level;
  request["radiographs"] = pair_hash;
  request["atlas"] = atlas_hash;
  request["patient"] = optional_text_input(parts, artifacts, "patient");
  RequestViews views = request_views(pair);
  request["views"] = std::move(views.views);
  request["images"] = std::move(views.images);
  request["bones"] = bone_outlines(pair, artifacts.get(atlas_hash), level);
  request["limits"] = {{"points_per_correction", image::kMaxPointsPerCorrection},
                       {"points", image::kMaxCorrectionPoints}};
  return request;
}

workflow::ManualEvaluation evaluate_outline_review(const Json& request, const Json& submission) {
  workflow::ManualEvaluation evaluation;
  evaluation.values = Json::object();
  std::vector<std::string>& reasons = evaluation.reasons;
  if (!submission.is_object()) {
    reasons.emplace_back(
        "the submission must be an object {\"decision\": \"accept\"} or {\"decision\": "
        "\"correct\", \"corrections\": [{\"bone\", \"view\", \"points\": [[u, v], ...]}]}");
    return evaluation;
  }
  for (const auto& [key, value] : submission.items()) {
    if (key != "decision" && key != "corrections") {
      reasons.push_back("unknown field '" + key + "'; a submission has 'decision' and, to " +
                        "correct, 'corrections'");
    }
  }
  const Json decision = submission.value("decision", Json());
  image::OutlineCorrections verdict;
  if (decision == "accept") {
    verdict.decision = image::OutlineDecision::kAccept;
    const Json corrections = submission.value("corrections", Json::array());
    if (!corrections.is_array() || !corrections.empty()) {
      reasons.emplace_back(
          "'corrections' must be empty (or absent) when the decision is \"accept\"; hint: "
          "decision \"correct\" submits corrections");
    }
  } else if (decision == "correct") {
    verdict.decision = image::OutlineDecision::kCorrect;
    const ReviewTargets targets = targets_of(request);
    const Json corrections = submission.value("corrections", Json());
    if (!corrections.is_array() || corrections.empty()) {
      reasons.emplace_back(
          "'corrections' must be a non-empty list of {\"bone\", \"view\", \"points\": [[u, v], "
          "...]} when the decision is \"correct\"");
    } else {
      std::set<std::pair<std::string, std::string>> seen;
      std::size_t total = 0;  // every point given, counted or not
      for (const Json& entry : corrections) {
        if (entry.is_object() && entry.contains("points") && entry["points"].is_array()) {
          total += entry["points"].size();
        }
      }
      for (std::size_t k = 0; k < corrections.size(); ++k) {
        std::optional<image::OutlineCorrection> correction =
            read_correction(corrections[k], k, targets, reasons);
        if (!correction) continue;
        if (!seen.insert({correction->bone, correction->view}).second) {
          reasons.push_back("corrections[" + std::to_string(k) + "]: bone '" + correction->bone +
                            "' in view '" + correction->view +
                            "' is corrected twice; hint: put all its points in one entry");
          continue;
        }
        verdict.corrections.push_back(std::move(*correction));
      }
      if (total > image::kMaxCorrectionPoints) {
        reasons.push_back("the corrections hold " + std::to_string(total) +
                          " points in all, at most " + std::to_string(image::kMaxCorrectionPoints) +
                          " are allowed");
      }
    }
  } else {
    reasons.push_back(R"('decision' must be "accept" or "correct", got )" + decision.dump());
  }
  if (!reasons.empty()) return evaluation;
  const Json radiographs = request.value("radiographs", Json());
  const Json atlas = request.value("atlas", Json());
  verdict.radiographs = radiographs.is_string() ? radiographs.get<std::string>() : "";
  verdict.atlas = atlas.is_string() ? atlas.get<std::string>() : "";
  image::sort_outline_corrections(verdict);
  try {
    std::string text = image::outline_corrections_to_json_text(verdict);
    evaluation.values = Json::parse(text);
    evaluation.outputs["corrections"] = {workflow::PortType::kOutlineCorrections, std::move(text)};
  } catch (const InvalidInputError& error) {
    reasons.push_back(std::string("the task's request is malformed (made by another mmm?): ") +
                      error.what());
  }
  return evaluation;
}

}  // namespace mmm::worklists

#include "worklists/task_views.h"

#include <Eigen/LU>

#include "core/bounded_json.h"
#include "core/errors.h"

namespace mmm::worklists {

RequestViews request_views(const image::RadiographPair& pair) {
  RequestViews out;
  for (const image::RadiographFile& file : pair.views) {
    const image::RadiographView& view = file.view;
    nlohmann::json P = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) {
      P.push_back({view.P(r, 0), view.P(r, 1), view.P(r, 2), view.P(r, 3)});
    }
    const std::string sha = pair.image_sha256(view.name);
    nlohmann::json origin = nullptr;
    const auto known = pair.origins.find(file.image);
    if (known != pair.origins.end()) {
      // A DICOM radiograph's own window, and its SOP Instance UID's hash for
      // the audit trail (the request is recorded with every decision).
      origin = {{"window", {known->second.window_centre, known->second.window_width}},
                {"sop_instance_uid_sha256", known->second.sop_instance_uid_sha256}};
    }
    out.views.push_back({{"name", view.name},
                         {"dicom", origin},
                         {"width", view.width},
                         {"height", view.height},
                         {"pixel_spacing_mm", view.pixel_spacing_mm},
                         {"model", image::projection_model_name(view.model)},
                         {"P", P},
                         {"image_sha256", sha}});
    out.images[view.name] = sha;
  }
  return out;
}

std::vector<image::RadiographView> views_of_request(const nlohmann::json& request) {
  std::vector<image::RadiographView> views;
  for (const nlohmann::json& entry : request.at("views")) {
    image::RadiographView view;
    view.name = entry.at("name").get<std::string>();
    view.width = entry.at("width").get<int>();
    view.height = entry.at("height").get<int>();
    view.pixel_spacing_mm = entry.at("pixel_spacing_mm").get<double>();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) view.P(r, c) = entry.at("P").at(r).at(c).get<double>();
    }
    // Requests written before slot-scanning views existed have no model.
    const auto model = entry.find("model");
    if (model != entry.end()) {
      const std::optional<image::ProjectionModel> known =
          image::projection_model_from_name(model->get<std::string>());
      if (!known) {
        throw InvalidInputError("the task's view '" + view.name + "' has the unknown model '" +
                                model->get<std::string>() + "'");
      }
      view.model = *known;
    }
    view.source_mm = -view.P.leftCols<3>().inverse() * view.P.col(3);
    views.push_back(view);
  }
  return views;
}

const workflow::ParamValue& key_param(const workflow::CacheKeyParts& parts, const char* name,
                                      const char* what) {
  const auto it = parts.params.find(name);
  if (it == parts.params.end()) {
    throw InvalidInputError(std::string(what) + ": parameter '" + name +
                            "' is missing from the node's key (made by an older mmm?)");
  }
  return it->second;
}

std::string optional_text_input(const workflow::CacheKeyParts& parts,
                                const workflow::ArtifactStore& artifacts, const char* port) {
  const auto input = parts.input_hashes.find(port);
  if (input == parts.input_hashes.end()) return {};
  const nlohmann::json value = parse_json_or_discarded(artifacts.get(input->second));
  return value.is_string() ? value.get<std::string>() : std::string();
}

}  // namespace mmm::worklists

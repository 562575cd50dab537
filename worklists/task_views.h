#pragma once
// The radiograph views as a task's request shows them (the landmark and
// outline review stations alike), and the key-part readers their request
// builders share.
//
//   "views":  [{"name": "frontal", "width": 970, "height": 2839,
//               "pixel_spacing_mm": 0.38, "P": [[...], [...], [...]],
//               "image_sha256": "..."}, ...]      in the pair's order
//   "images": {"frontal": "<sha256>", ...}       the images the operator sees
//                                                (recorded in the audit trail)

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/image/projection.h"
#include "core/image/radiograph_pair.h"
#include "workflow/node_spec.h"
#include "workflow/store/artifact_store.h"
#include "workflow/study/cache_key.h"

namespace mmm::worklists {

struct RequestViews {
  nlohmann::json views = nlohmann::json::array();
  nlohmann::json images = nlohmann::json::object();
};

RequestViews request_views(const image::RadiographPair& pair);

// The views of a request back (name, size, spacing, P and source); throws
// nlohmann::json exceptions for a request not written by request_views.
std::vector<image::RadiographView> views_of_request(const nlohmann::json& request);

// The parameter `name` of the key parts; InvalidInputError naming `what`
// (e.g. "landmark task") when the key lacks it.
const workflow::ParamValue& key_param(const workflow::CacheKeyParts& parts, const char* name,
                                      const char* what);

// The text of the optional String input `port` ("" when unconnected or not a
// JSON string).
std::string optional_text_input(const workflow::CacheKeyParts& parts,
                                const workflow::ArtifactStore& artifacts, const char* port);

}  // namespace mmm::worklists

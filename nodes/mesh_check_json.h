#pragma once
// JSON form of a mesh health report, shared by the measure_mesh node and
// `mmm mesh info|survey` so that both speak the same keys.

#include <nlohmann/json.hpp>

#include "core/mesh/mesh_check.h"

namespace mmm::nodes {

// Every count of the report plus closed/manifold/orientation_consistent/
// watertight and the list of problems in words.
nlohmann::json mesh_check_json(const mesh::MeshCheckReport& report);

}  // namespace mmm::nodes

#pragma once
// The muscles a node's `muscles` parameter names (comma-separated, see
// name_list.h); every muscle of the atlas when it names none.

#include <string>
#include <string_view>
#include <vector>

#include "core/atlas/atlas.h"

namespace mmm::nodes {

// Throws InvalidInputError "NODE: parameter 'muscles': the atlas has no
// muscle 'X'" for a name the atlas does not have.
std::vector<const atlas::Muscle*> selected_muscles(const atlas::Atlas& atlas,
                                                   const std::string& names, std::string_view node);

}  // namespace mmm::nodes

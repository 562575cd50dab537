#include "nodes/muscle_selection.h"

#include "core/errors.h"
#include "nodes/name_list.h"

namespace mmm::nodes {

std::vector<const atlas::Muscle*> selected_muscles(const atlas::Atlas& atlas,
                                                   const std::string& names,
                                                   std::string_view node) {
  std::vector<const atlas::Muscle*> muscles;
  for (const std::string& name : split_names(names)) {
    const atlas::Muscle* muscle = atlas.find_muscle(name);
    if (muscle == nullptr) {
      throw InvalidInputError(std::string(node) +
                              ": parameter 'muscles': the atlas has no muscle '" + name + "'");
    }
    muscles.push_back(muscle);
  }
  if (muscles.empty()) {
    for (const atlas::Muscle& muscle : atlas.muscles) muscles.push_back(&muscle);
  }
  return muscles;
}

}  // namespace mmm::nodes

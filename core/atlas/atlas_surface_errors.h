#pragma once
// How far an estimated atlas (a scaled atlas) lies from the true one (a
// synthetic patient's own atlas): for every bone and muscle of the
// estimate, the symmetric area-weighted surface distance (surface_distance.h)
// between its mesh and the same element's mesh in the truth, at one level
// of detail. The report's "ground-truth surface errors".

#include <filesystem>
#include <string>
#include <vector>

#include "core/mesh/surface_distance.h"

namespace mmm::atlas {

struct ElementSurfaceError {
  std::string element;
  std::string kind;  // "bone" or "muscle"
  mesh::SurfaceDistance distance;
};

// Bones first, then muscles, each in the estimate's order. Throws
// InvalidInputError naming an element of the estimate that the truth lacks,
// IoError for an atlas or mesh that cannot be read.
std::vector<ElementSurfaceError> atlas_surface_errors(const std::filesystem::path& estimate_dir,
                                                      const std::filesystem::path& truth_dir,
                                                      const std::string& level = "full",
                                                      int threads = 2);

}  // namespace mmm::atlas

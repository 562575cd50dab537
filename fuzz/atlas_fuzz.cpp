// The atlas manifest (atlas.yaml) and the atlas build recipe.
#include <exception>

#include "core/atlas/atlas_io.h"
#include "core/atlas/atlas_recipe.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"

namespace mmm::fuzz {

void atlas_manifest(const std::uint8_t* data, std::size_t size) {
  try {
    (void)as_file(data, size, "atlas.yaml");
    (void)atlas::read_atlas(scratch_folder());
  } catch (const std::exception&) {
  }
}

void atlas_recipe(const std::uint8_t* data, std::size_t size) {
  try {
    (void)atlas::read_atlas_recipe(as_file(data, size, "recipe.yaml"));
  } catch (const std::exception&) {
  }
}

}  // namespace mmm::fuzz

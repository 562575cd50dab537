// 3D Slicer markups (.mrk.json) landmark files.
#include <exception>

#include "core/landmarks/slicer_markups.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"

namespace mmm::fuzz {

void markups(const std::uint8_t* data, std::size_t size) {
  try {
    (void)landmarks::read_slicer_markups(as_file(data, size, "input.mrk.json"));
  } catch (const std::exception&) {
  }
}

}  // namespace mmm::fuzz

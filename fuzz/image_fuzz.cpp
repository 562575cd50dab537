// PNG decoding and the radiograph views sidecar (views.json).
#include <exception>
#include <string>

#include "core/image/png.h"
#include "core/image/projection.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"

namespace mmm::fuzz {

void png(const std::uint8_t* data, std::size_t size) {
  try {
    (void)image::decode_png("input.png", std::string(as_text(data, size)));
  } catch (const std::exception&) {
  }
}

void views(const std::uint8_t* data, std::size_t size) {
  try {
    (void)image::parse_view_sidecar(std::string(as_text(data, size)), "views.json");
  } catch (const std::exception&) {
  }
}

}  // namespace mmm::fuzz

// OpenSim text formats: marker trajectories (.trc), storage/motion (.mot),
// models (.osim).
#include <exception>

#include "core/opensim/mot.h"
#include "core/opensim/osim_model.h"
#include "core/opensim/trc.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/fuzz_targets.h"

namespace mmm::fuzz {

void trc(const std::uint8_t* data, std::size_t size) {
  try {
    (void)opensim::parse_trc(as_text(data, size), "input.trc");
  } catch (const std::exception&) {
  }
}

void mot(const std::uint8_t* data, std::size_t size) {
  try {
    (void)opensim::parse_mot(as_text(data, size), "input.mot");
  } catch (const std::exception&) {
  }
}

void osim(const std::uint8_t* data, std::size_t size) {
  try {
    (void)opensim::parse_osim(as_text(data, size), "input.osim");
  } catch (const std::exception&) {
  }
}

}  // namespace mmm::fuzz

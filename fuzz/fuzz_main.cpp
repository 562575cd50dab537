// The libFuzzer entry points of mmm_fuzz: the target named by
// $MMM_FUZZ_TARGET (fuzz/run sets it) runs on each input.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <utility>

#include "fuzz/fuzz_targets.h"

namespace {

constexpr std::pair<std::string_view, mmm::fuzz::Target> kTargets[] = {
    {"stl", mmm::fuzz::stl},
    {"ply", mmm::fuzz::ply},
    {"obj", mmm::fuzz::obj},
    {"off", mmm::fuzz::off},
    {"vtp", mmm::fuzz::vtp},
    {"trc", mmm::fuzz::trc},
    {"mot", mmm::fuzz::mot},
    {"osim", mmm::fuzz::osim},
    {"workflow_yaml", mmm::fuzz::workflow_yaml},
    {"atlas_manifest", mmm::fuzz::atlas_manifest},
    {"atlas_recipe", mmm::fuzz::atlas_recipe},
    {"markups", mmm::fuzz::markups},
    {"submission", mmm::fuzz::submission},
    {"views", mmm::fuzz::views},
    {"png", mmm::fuzz::png},
    {"dicom", mmm::fuzz::dicom},
    {"deidentified", mmm::fuzz::deidentified},
};

mmm::fuzz::Target g_target = nullptr;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  const char* name = std::getenv("MMM_FUZZ_TARGET");
  for (const auto& [target_name, target] : kTargets) {
    if (name != nullptr && target_name == name) g_target = target;
  }
  if (g_target == nullptr) {
    std::fprintf(stderr, "mmm_fuzz: set MMM_FUZZ_TARGET to one of:");
    for (const auto& entry : kTargets) {
      std::fprintf(stderr, " %.*s", static_cast<int>(entry.first.size()), entry.first.data());
    }
    std::fprintf(stderr, "\n");
    std::exit(2);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  g_target(data, size);
  return 0;
}

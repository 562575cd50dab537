#include "workflow/store/shared_store.h"

#include <system_error>

#include "core/errors.h"

namespace mmm::workflow {

namespace fs = std::filesystem;

std::optional<fs::path> find_shared_store(const fs::path& study_dir) {
  fs::path folder = fs::absolute(study_dir).lexically_normal();
  for (int level = 0; level < kSharedStoreDepth; ++level) {
    if (!folder.has_parent_path() || folder.parent_path() == folder) break;
    folder = folder.parent_path();
    std::error_code error;
    const fs::path candidate = folder / kSharedStoreFolder;
    if (fs::is_directory(candidate, error)) return candidate;
  }
  return std::nullopt;
}

fs::path create_shared_store(const fs::path& root) {
  fs::path store = root / kSharedStoreFolder;
  std::error_code error;
  fs::create_directories(store, error);
  if (!fs::is_directory(store)) {
    throw IoError(store, "cannot create the shared artifact store" +
                             (error ? ": " + error.message() : std::string(": not a folder")) +
                             "; hint: check that the root folder is writable");
  }
  return store;
}

}  // namespace mmm::workflow

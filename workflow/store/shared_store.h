#pragma once
// The store shared by the studies under one root folder (a cohort): the
// folder `<root>/.mmm-store`, laid out as a study's artifacts/ folder. A
// study whose folder lies under such a root (at most kSharedStoreDepth
// levels below it, as the worklist finds studies) shares its blobs with it
// (ArtifactStore::share_with): an artifact identical across the studies (the
// atlas, the generic atlas's hulls, the motion trial) takes its size once.
// Each study keeps its own database, audit trail and a hard link to every
// blob it uses; collect_garbage (worklists/root_gc.h) removes what no study
// links any more.

#include <filesystem>
#include <optional>

namespace mmm::workflow {

inline constexpr const char* kSharedStoreFolder = ".mmm-store";
inline constexpr int kSharedStoreDepth = 4;

// The shared store of the root that holds `study_dir`: the nearest
// `.mmm-store` folder in the folders above it, at most kSharedStoreDepth
// levels up; std::nullopt when there is none.
std::optional<std::filesystem::path> find_shared_store(const std::filesystem::path& study_dir);

// Creates `<root>/.mmm-store` (and `root`) if missing; returns its path.
// Throws IoError when it cannot be created.
std::filesystem::path create_shared_store(const std::filesystem::path& root);

}  // namespace mmm::workflow

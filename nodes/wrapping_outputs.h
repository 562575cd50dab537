#pragma once
// The outputs both wrapping pathways write (wrap_muscles, simulate_muscles),
// from their common result (wrapping::MuscleWrapping): the metrics and
// action-line CSVs and the ParaView animation.

#include <filesystem>
#include <string>

#include "core/atlas/atlas.h"
#include "core/wrapping/muscle_wrapping.h"
#include "workflow/node_context.h"

namespace mmm::nodes {

// One row per muscle and frame: volume error, bone and muscle penetration,
// contacts, smoothness, time.
std::string metrics_csv(const wrapping::MuscleWrapping& wrapped);

// One row per action line and frame: length and moment arms.
std::string lines_csv(const wrapping::MuscleWrapping& wrapped);

// A folder bundle (wrapping.pvd + .vtp per frame) of every `stride`-th
// frame: the bones at `bone_level`, the structures they carry, the muscles
// and the action lines. Written in the node's scratch folder.
std::string animation_bundle(const workflow::NodeContext& context,
                             const wrapping::MuscleWrapping& wrapped, const atlas::Atlas& atlas,
                             const std::filesystem::path& atlas_dir, const std::string& bone_level,
                             int stride);

}  // namespace mmm::nodes

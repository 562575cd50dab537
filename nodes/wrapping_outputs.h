#pragma once
// What both wrapping pathways (wrap_muscles, simulate_muscles) share: the
// fused motion they read, and the outputs they write from their common
// result (wrapping::MuscleWrapping): the metrics and action-line CSVs, the
// plot and the ParaView animation.

#include <filesystem>
#include <string>

#include "core/atlas/atlas.h"
#include "core/motion/motion_fusion.h"
#include "core/wrapping/muscle_wrapping.h"
#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

// The input 'motion': fuse_motion's motion of an atlas. Throws
// InvalidInputError (naming `node` and the input, with a hint) when it is not
// JSON, not a motion, or drives an OpenSim model instead of an atlas.
motion::FusedMotion atlas_motion_input(const workflow::NodeContext& context,
                                       const std::string& node);

// Declares the parameters 'animation_stride' and 'bone_level' and the
// outputs 'wrapped', 'animation', 'metrics', 'lines' and 'plot' that
// set_wrapping_outputs fills.
workflow::NodeSpec& add_wrapping_outputs(workflow::NodeSpec& spec);

// Sets the outputs 'metrics', 'lines', 'plot' (titled `plot_title`),
// 'wrapped' (core/wrapping/muscle_frames.h, written by `pathway`) and
// 'animation' (parameters 'bone_level' and 'animation_stride').
void set_wrapping_outputs(workflow::NodeContext& context, const wrapping::MuscleWrapping& wrapped,
                          const atlas::Atlas& atlas, const std::filesystem::path& atlas_dir,
                          const std::string& plot_title, const std::string& pathway);

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

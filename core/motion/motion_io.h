#pragma once
// The BonePoses artifact of a fused motion, as JSON (the workflow's
// serialisation of that port type; downstream nodes read it back):
//
//   { "format": "mmm-motion 1",
//     "model": "subject01", "model_kind": "atlas" | "osim",
//     "frame": "...",                          what the poses map, in words
//     "times": [t0, ...],                      s
//     "trial_frames": [i0, ...],               0-based rows of the trial
//     "coordinates": {"names": [...], "units": ["rad"|"mm", ...],
//                     "values": [[q(t0)...], ...]},
//     "bodies": {"names": [...], "poses": [[[r00 r01 r02 t0 r10 ... t2] per body] per frame]},
//     "markers": {"names": [...], "errors_mm": [[e or null, ...] per frame]} }
//
// A pose is the 3 by 4 matrix [R | t] row by row: body coordinates (for an
// atlas, its rest-pose frame; for an OpenSim model, the body frame; mm) to
// the trial's lab frame (mm).

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "core/motion/motion_fusion.h"

namespace mmm::motion {

nlohmann::json motion_to_json(const FusedMotion& motion, const std::string& model,
                              const std::string& model_kind);

// Reads what motion_to_json writes (times, trial frames, coordinates, body
// names and poses, marker names and errors). Throws InvalidInputError,
// starting with `what`, naming the first field that is missing or
// inconsistent (counts that disagree, a pose without 12 numbers, a
// non-finite number where one is required).
FusedMotion motion_from_json(const nlohmann::json& json, std::string_view what);

}  // namespace mmm::motion

#pragma once
// An operator's verdict on the bone outlines projected onto a patient's
// radiographs (the outline review station): accepted as they are, or
// corrected by points where the operator says a bone's true edge lies in a
// view. The value of the OutlineCorrections port type; a fitting node reads
// it with read_outline_corrections.
//
// Canonical JSON text (2-space indent, keys sorted, a final newline):
//   {"format": "mmm-outline-corrections", "version": 1,
//    "decision": "accept" | "correct",
//    "corrections": [{"bone": "femur_r", "view": "frontal",
//                     "points_px": [[u, v], ...]}, ...],
//    "radiographs": "<artifact hash of the radiograph pair>",
//    "atlas": "<artifact hash of the atlas whose outlines were reviewed>"}
//   points_px  pixel positions (u right, v down, pixel centres at +0.5, as
//              core/image/projection.h) in the named view, in the order the
//              operator placed them; 1 to kMaxPointsPerCorrection per entry
//              and kMaxCorrectionPoints in all
//   corrections  sorted by bone, then view; one entry per (bone, view);
//              empty when the decision is "accept", non-empty for "correct"

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::image {

inline constexpr std::size_t kMaxPointsPerCorrection = 200;
inline constexpr std::size_t kMaxCorrectionPoints = 2000;

enum class OutlineDecision { kAccept, kCorrect };

struct OutlineCorrection {
  std::string bone;                        // atlas bone name, e.g. "femur_r"
  std::string view;                        // radiograph view name, e.g. "frontal"
  std::vector<Eigen::Vector2d> points_px;  // pixels of that view
};

struct OutlineCorrections {
  OutlineDecision decision = OutlineDecision::kAccept;
  std::vector<OutlineCorrection> corrections;  // sorted by (bone, view), unique
  std::string radiographs;                     // artifact hash (64 hex)
  std::string atlas;                           // artifact hash (64 hex)
};

// Sorts the corrections by (bone, view): what the text holds.
void sort_outline_corrections(OutlineCorrections& corrections);

// The canonical text (see the file comment) of the sorted corrections.
// Throws InvalidInputError for what read_outline_corrections would refuse.
std::string outline_corrections_to_json_text(const OutlineCorrections& corrections);

// Parses and checks the text. `source` names it in messages (a file path,
// "input 'corrections'"). Throws InvalidInputError "<source>: <where>:
// <problem>", e.g. "<source>: corrections[1].points_px[3]: must be [u, v],
// two finite numbers (pixels), got [1]": not JSON, another format or
// version, a missing or mistyped field, an unknown decision, corrections
// with "accept" or none with "correct", an empty bone or view name, a
// repeated (bone, view), out of order entries, an empty point list or too
// many points. Unknown extra fields are refused (a newer writer's meaning
// would be lost).
OutlineCorrections read_outline_corrections(std::string_view text, std::string_view source);

}  // namespace mmm::image

#pragma once
// Is an atlas fit to start a study from? `mmm atlas check` runs this and
// fails when any answer is no:
//   - every bone, muscle, cartilage and ligament mesh (every level) is a
//     closed 2-manifold, consistently oriented outward;
//   - no muscle enters a bone deeper than `max_penetration_mm` at rest;
//   - the fibre part of every action line lies at least `min_inside_fraction`
//     inside its own muscle: the inside length (the polyline sampled every
//     `sample_step_mm`; inside = winding number > 1/2) over the line's length
//     less the muscle's tendon slack length (muscle surfaces end where the
//     tendon begins: the iliotibial band of the tensor fasciae latae, the
//     patellar tendon of the quadriceps);
//   - the bones fit together as in a person (anatomy_check.h: no bone in
//     another, none away from its neighbours, joints closed, the femoral
//     head in the acetabulum, the cartilages of each joint meeting, every
//     cartilage and ligament on its bones);
//   - the required landmarks exist (kRequiredLandmarks);
//   - every reference resolves (read_atlas checks that; a failure is
//     reported as a problem here rather than thrown).
// It also measures each muscle (volume, triangles) for the report.

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/atlas/anatomy_check.h"
#include "core/atlas/atlas.h"

namespace mmm::atlas {

struct AtlasCheckOptions {
  double max_penetration_mm = 1.0;   // deepest muscle vertex inside a bone
  double min_inside_fraction = 0.8;  // of each action line, inside its muscle
  double sample_step_mm = 1.0;       // spacing of action-line samples
  AnatomyLimits anatomy;             // how the bones fit together (anatomy_check.h)
};

struct MeshHealth {
  std::string element;  // bone, muscle or structure name
  std::string level;    // "full", "lod1", ...
  int faces = 0;
  bool closed = false;
  bool manifold = false;
  bool oriented = false;  // consistently oriented, outward (positive volume)
  double volume_mm3 = 0.0;
};

struct ActionLineCheck {
  std::string muscle;
  std::string line;
  double length_mm = 0.0;
  double inside_fraction = 0.0;  // of the whole length
  double tendon_mm = 0.0;        // the muscle's tendon slack length, at most 3/4 of the path
  // Inside length over the fibre part (length - tendon), at most 1: what the
  // check holds against min_inside_fraction.
  double fibre_part_inside_fraction = 0.0;
};

struct MuscleCheck {
  std::string name;
  double volume_mm3 = 0.0;  // full level
  int faces = 0;            // full level
  double max_penetration_mm = 0.0;
  std::string deepest_bone;               // the bone it enters most, empty if none
  double min_inside_fraction = 1.0;       // fibre part, over its action lines (1 when it has none)
  double min_line_inside_fraction = 1.0;  // whole length, over its action lines
};

struct AtlasCheckReport {
  std::vector<MeshHealth> meshes;
  std::vector<MuscleCheck> muscles;
  std::vector<ActionLineCheck> action_lines;
  AnatomyReport anatomy;
  std::vector<std::string> problems;  // one sentence each; empty when the atlas passes

  [[nodiscard]] bool passed() const { return problems.empty(); }
};

// Checks the atlas in `dir` (read with read_atlas). Never throws for a bad
// atlas: an unreadable manifest or mesh is a problem in the report.
AtlasCheckReport check_atlas(const std::filesystem::path& dir,
                             const AtlasCheckOptions& options = {});

// The rest-pose polyline of an action line (conditional points whose
// coordinate's rest value lies outside their range are left out).
std::vector<Eigen::Vector3d> action_line_polyline(const Atlas& atlas, const ActionLine& line);

// Fraction of the polyline (by length, sampled every `step_mm`) inside the
// closed surface whose winding number `inside` reports. Samples include both
// ends; a zero-length line counts as its single point.
double inside_fraction(const std::vector<Eigen::Vector3d>& polyline, double step_mm,
                       const std::function<bool(const Eigen::Vector3d&)>& inside);

}  // namespace mmm::atlas

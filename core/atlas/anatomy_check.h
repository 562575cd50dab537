#pragma once
// The anatomy part of `mmm atlas check`: do the bones fit together as in a
// person? For the bones at rest (full level):
//   - no bone enters another deeper than `max_bone_overlap_mm`;
//   - every bone has a neighbour within `max_neighbour_gap_mm` (nothing
//     floats away from the skeleton);
//   - every articulation is closed to within `max_joint_gap_mm`: the bones
//     of each joint (the nearest pair across the two sides, welded bones
//     counted with their side) and the patella with the femur (bones tagged
//     `patella` and `femur`);
//   - the femoral head sits in the acetabulum: the landmarks
//     femoral_head_centre_r and acetabulum_centre_r (when both exist) within
//     `max_hip_centre_offset_mm`.
// Gaps are between the bone surfaces as segmented: where the cartilage is
// not part of a bone's surface the gap includes it.

#include <map>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/bone_contacts.h"
#include "core/mesh/mesh.h"

namespace mmm::atlas {

struct AnatomyLimits {
  double max_bone_overlap_mm = 1.0;
  double max_neighbour_gap_mm = 5.0;
  double max_joint_gap_mm = 8.0;
  double max_hip_centre_offset_mm = 3.0;
};

struct Articulation {
  std::string name;  // the joint's name, or "patellofemoral_r"
  std::string a;
  std::string b;
  double gap_mm = 0.0;
  double overlap_mm = 0.0;
};

struct AnatomyReport {
  std::vector<BoneContact> contacts;  // every pair within reach (max_neighbour_gap_mm + 5)
  std::map<std::string, double> nearest_neighbour_gap_mm;  // per bone
  std::vector<Articulation> articulations;
  double hip_centre_offset_mm = -1.0;  // -1: landmarks absent
};

// Measures and appends one sentence per failed limit to `problems`, naming
// the bones and the figure.
AnatomyReport check_anatomy(const Atlas& atlas,
                            const std::map<std::string, mesh::IndexedMesh>& bones,
                            const AnatomyLimits& limits, std::vector<std::string>& problems);

}  // namespace mmm::atlas

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
//     `max_hip_centre_offset_mm`;
//   - the joints' contact surfaces meet: for every articulation whose two
//     sides both carry cartilage, each facing pair of cartilages (one on
//     each side, bounding boxes within `cartilage_reach_mm`) has a gap of at
//     most `max_cartilage_gap_mm` and an overlap of at most
//     `max_cartilage_overlap_mm` (hip: femoral head and acetabulum; knee:
//     distal femur with each tibial plateau; patellofemoral; ankle: talus
//     and distal tibia). An articulation with cartilage on both sides but no
//     facing pair fails too;
//   - every cartilage and ligament reaches its bone(s) (gap at most
//     `max_structure_gap_mm`): nothing floats away from the bone carrying it.
// Bone gaps are between the bone surfaces as segmented: where the cartilage
// is not part of a bone's surface the gap includes it.

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
  double max_cartilage_gap_mm = 3.0;
  double max_cartilage_overlap_mm = 1.5;
  double cartilage_reach_mm = 10.0;
  double max_structure_gap_mm = 3.0;
};

struct Articulation {
  std::string name;  // the joint's name, or "patellofemoral_r"
  std::string a;
  std::string b;
  double gap_mm = 0.0;
  double overlap_mm = 0.0;
};

// Two cartilages facing each other across an articulation.
struct CartilageContact {
  std::string articulation;
  std::string a;  // cartilage on the articulation's first side
  std::string b;
  double gap_mm = 0.0;
  double overlap_mm = 0.0;
};

// A cartilage or ligament against one of its bones.
struct StructureAttachment {
  std::string structure;
  std::string bone;
  double gap_mm = 0.0;
};

struct AnatomyReport {
  std::vector<BoneContact> contacts;  // every pair within reach (max_neighbour_gap_mm + 5)
  std::map<std::string, double> nearest_neighbour_gap_mm;  // per bone
  std::vector<Articulation> articulations;
  std::vector<CartilageContact> cartilage_contacts;
  std::vector<StructureAttachment> structure_attachments;
  double hip_centre_offset_mm = -1.0;  // -1: landmarks absent
};

// Measures and appends one sentence per failed limit to `problems`, naming
// the bones (structures) and the figure. `structures` holds the surfaces of
// the atlas's cartilages and ligaments (none: those checks are skipped).
AnatomyReport check_anatomy(const Atlas& atlas,
                            const std::map<std::string, mesh::IndexedMesh>& bones,
                            const std::map<std::string, mesh::IndexedMesh>& structures,
                            const AnatomyLimits& limits, std::vector<std::string>& problems);

}  // namespace mmm::atlas

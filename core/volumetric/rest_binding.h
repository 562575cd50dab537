#pragma once
// How the volumetric model is tied to the skeleton at rest
// (muscle_simulation.h): each muscle's surface on its own nodes, the
// surface nodes moved out of the bones, the attachment nodes that follow
// their bones, and the element nodes anchored inside the bones.

#include <cstdint>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/mesh/mesh.h"
#include "core/volumetric/coarse_embedding.h"
#include "core/volumetric/lattice_tets.h"
#include "core/volumetric/tet_simulation.h"
#include "core/wrapping/posed_skeleton.h"

namespace mmm::volumetric {

// The surface of label l + 1 on its own nodes: faces renumbered, and the
// output nodes they came from.
struct MuscleSurface {
  mesh::IndexedMesh rest;
  std::vector<int> nodes;  // output node per vertex
};

MuscleSurface muscle_surface(const TetMesh& output, std::uint16_t label);

// The boundary nodes of a muscle within `reach` of one of its attachment
// areas follow that area's bone (nodes already `taken`, >= 0, are skipped).
// An area farther than that from every node is reached through a tendon the
// segmentation does not hold (the quadriceps' insertion on the tibia, the
// triceps surae's on the calcaneus): tying the belly's end rigidly to that
// bone would drag it around the joint, so the area is left out and the end
// follows the tissue around it. `gap` receives the largest distance from an
// area to the muscle, `left_out` the areas left out. Throws
// InvalidInputError for an area naming a face its bone does not have.
std::vector<DrivenNode> attachments(const atlas::Muscle& muscle, const MuscleSurface& surface,
                                    const wrapping::PosedBones& bones,
                                    const std::vector<int>& taken, double reach, double& gap,
                                    int& left_out);

// Output nodes on a muscle's boundary inside a bone at rest, or nearer it
// than `clearance`, moved onto the bone's surface plus the clearance (a
// lattice's staircase reaches up to half a cell diagonal, `cell`, into a
// bone). Returns the largest move (mm); `moved_count` receives the nodes
// moved.
double move_out_of_bones(EmbeddedModel& model, const std::vector<int>& boundary_nodes,
                         const wrapping::PosedBones& bones, double clearance, double cell,
                         int threads, int& moved_count);

// Element nodes inside a bone at rest (within `reach` of its surface)
// follow it: an element reaching into a bone (across a thin wing, say)
// moves with the bone instead of being pushed out of it on both sides.
// Not anchored: nodes within `joint_clearance` of a bone on another body
// (a joint's other side, where tissue slides over both), and the corners
// of an element reaching into two bones.
std::vector<DrivenNode> element_anchors(const TetMesh& elements, const wrapping::PosedBones& bones,
                                        double reach, double joint_clearance, int threads);

}  // namespace mmm::volumetric

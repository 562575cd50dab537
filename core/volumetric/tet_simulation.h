#pragma once
// Quasi-static simulation of a labelled tetrahedral model (lattice_tets.h):
// projective dynamics (Bouaziz et al. 2014), one prefactored linear system
// for the whole model, so muscles that share interface nodes move as one
// body and cannot enter each other without inverting an element.
//
// Per frame, from the previous frame's positions x_prev, iterate:
//   local    per tetrahedron, F = D_s D_m^-1 (deformed over rest edges), its
//            SVD U S V^T with reflections folded into the last singular value:
//              shape   P_s = U V^T                 (nearest rotation)
//              volume  P_v = U S' V^T, S' = S / (s1 s2 s3)^(1/3) (det 1)
//            contact: for every node within contact_reach_mm of a bone at
//            rest, the point it should be at: itself when clear of the bone,
//            else the bone's surface plus bone_clearance_mm (q_i)
//   global   minimise  sum_t V_t (w_s |F_t - P_s|^2 + w_v |F_t - P_v|^2)
//                    + w_a sum_driven |x_i - target_i|^2
//                    + w_c sum_checked |x_i - q_i|^2
//                    + w_m sum_i m_i |x_i - x_prev_i|^2
//            a constant sparse SPD system (factored once, CHOLMOD), three
//            right-hand sides (x, y, z). The contact term weighs every
//            checked node all the time, so the matrix never changes; for a
//            node clear of its bone it pulls towards where the node already
//            is, which slows it but does not bias where it converges.
//   volume   each muscle's volume back to its rest volume: one Newton step
//            along the volume's gradient on its boundary nodes (not the
//            driven ones), muscle after muscle
// Driven nodes (attachments) follow their bone rigidly: target = pose * rest.
// The inertia term (m_i the node's share of volume) keeps a part with no
// driven node defined; w_m is small, so it barely holds the model back.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/volumetric/lattice_tets.h"

namespace mmm::volumetric {

struct SimulationOptions {
  double shape_weight = 1.0;
  double volume_weight = 1.0;      // per tetrahedron; each muscle's total is restored exactly
  double driven_weight = 1.0e4;    // against the tetrahedra's, per node
  double inertia_weight = 1.0e-3;  // against the tetrahedra's
  double contact_weight = 10.0;    // against the tetrahedra's, per checked node
  int iterations = 10;             // local-global rounds per frame
  double bone_clearance_mm = 0.1;
  double contact_reach_mm = 15.0;  // nodes this close to a bone at rest are checked
  int threads = 1;
};

// A node that follows a bone rigidly (an attachment).
struct DrivenNode {
  int node = 0;
  int bone = 0;  // index into the bones given to the simulation
};

struct FrameStats {
  double max_bone_depth_mm = 0.0;     // deepest checked node inside a bone, after the frame
  int nodes_in_bones = 0;             // checked nodes inside a bone
  int inverted = 0;                   // tetrahedra with det F <= 0
  std::vector<double> volume_change;  // per label (index label - 1): volume / rest - 1
  double seconds = 0.0;
};

class TetSimulation {
 public:
  // `bones`: closed outward surfaces in the rest frame of the model, each
  // moved per frame by its pose. Throws InvalidInputError for an empty mesh,
  // an inverted or flat rest tetrahedron, a driven node or bone index out of
  // range, a null or invalid bone surface, or non-positive or non-finite
  // weights / iterations.
  TetSimulation(TetMesh rest, std::vector<DrivenNode> driven,
                const std::vector<const mesh::IndexedMesh*>& bones,
                const SimulationOptions& options = {});
  ~TetSimulation();
  TetSimulation(TetSimulation&&) noexcept;
  TetSimulation& operator=(TetSimulation&&) noexcept;

  // One frame: `poses[b]` maps bone b's rest frame to this frame's. Starts
  // from the previous frame (warm start). Throws InvalidInputError when the
  // number of poses differs from the number of bones or a pose is not finite.
  FrameStats step(const std::vector<Eigen::Isometry3d>& poses);

  [[nodiscard]] const Eigen::MatrixX3d& positions() const;
  [[nodiscard]] const TetMesh& rest() const;
  // Nodes checked against each bone (contact_reach_mm at rest).
  [[nodiscard]] int checked_nodes() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mmm::volumetric

#pragma once
// Quasi-static simulation of a labelled tetrahedral model: projective
// dynamics (Bouaziz et al. 2014) on one prefactored linear system for the
// whole model, so muscles that share interface nodes move as one body and
// cannot enter each other without inverting an element.
//
// The simulated tetrahedra (the elements, x) may be coarser than the model
// whose muscle boundaries are the outputs (coarse_embedding.h): every output
// node is a fixed combination of element nodes, y = W x. Attachments, bone
// contacts and the per-muscle volumes act on the output nodes; the elements
// carry the elasticity.
//
// Per frame, from the previous frame's positions x_prev, iterate:
//   local    per element, F = D_s D_m^-1 (deformed over rest edges):
//              shape   P_s = R, the rotation of F's polar decomposition
//                      (Mueller et al. 2016, warm-started from the
//                      element's rotation of the last round)
//              volume  P_v = F / det(F)^(1/3) (det 1; R when F is inverted)
//            contact: for every output node on a muscle boundary within
//            contact_reach_mm of a bone at rest, the point it should be at:
//            itself when clear of the bone, else the bone's surface plus
//            bone_clearance_mm (q_i)
//   global   minimise  sum_t V_t (w_s |F_t - P_s|^2 + w_v |F_t - P_v|^2)
//                    + w_a sum_driven |W_i x - target_i|^2
//                    + w_c sum_checked |W_i x - q_i|^2
//                    + w_m sum_i m_i |x_i - xhat_i|^2
//            a constant sparse SPD system (factored once, CHOLMOD), three
//            right-hand sides (x, y, z). The contact term weighs every
//            checked node all the time, so the matrix never changes; for a
//            node clear of its bone it pulls towards where the node already
//            is, which slows it but does not bias where it converges.
//   volume   every muscle's volume (its output boundary) back to its rest
//            volume: Newton steps along the volumes' gradients carried to
//            the element nodes (W^T dV/dy), all muscles at once (the small
//            Gram system of the gradients, since neighbours share nodes);
//            element nodes that carry an attachment do not move
// Driven output nodes (attachments) follow their bone rigidly:
// target = pose * rest. The warm start xhat carries each element node by a
// blend of the bones' motions since the last frame (nearer bones weigh
// more); the term pulling towards it (m_i the node's share of volume) keeps a
// part with no driven node defined, is blind to a rigid motion of
// everything, and is weak (w_m small).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/volumetric/coarse_embedding.h"
#include "core/volumetric/lattice_tets.h"

namespace mmm::volumetric {

struct SimulationOptions {
  double shape_weight = 1.0;
  double volume_weight = 1.0;      // per tetrahedron; each muscle's total is restored exactly
  double driven_weight = 1.0e4;    // against the tetrahedra's, per node
  double inertia_weight = 1.0e-3;  // against the tetrahedra's
  double contact_weight = 10.0;    // against the tetrahedra's, per checked node
  // Separate muscles (EmbeddedModel::interfaces): each pair of interface
  // nodes is tied by w_i |y_a - y_b - p|^2. Stick: p = 0. Slide: p is the
  // part of y_a - y_b along the interface (the plane normal to a's muscle
  // surface at a), so the muscles slide along each other but neither part
  // nor enter each other there. The warm start carries a muscle by its
  // neighbours' motion across the interfaces when they stick, and when they
  // slide only a muscle with nothing driven.
  bool slide = false;
  double interface_weight = 1000.0;  // against the tetrahedra's, per pair
  int iterations = 10;               // local-global rounds per frame
  int rotation_iterations = 2;       // polar-decomposition steps per element and round
  double bone_clearance_mm = 0.1;
  double contact_reach_mm = 15.0;  // nodes this close to a bone at rest are checked
  int threads = 1;
};

// A node that follows a bone rigidly: an output node (an attachment), or
// an element node (one inside the bone at rest, so that an element reaching
// into a bone moves with it).
struct DrivenNode {
  int node = 0;  // output node, or element node when `element`
  int bone = 0;  // index into the bones given to the simulation
  bool element = false;
};

struct FrameStats {
  double max_bone_depth_mm = 0.0;       // deepest checked node inside a bone, after the frame
  int nodes_in_bones = 0;               // checked nodes inside a bone
  int inverted = 0;                     // elements with det F <= 0
  std::vector<int> inverted_per_label;  // per element label (index label - 1)
  std::vector<double> volume_change;    // per label (index label - 1): volume / rest - 1
  // Separate muscles: the largest distance across the interface (normal to
  // it at a) and along it (how far the sides slid) over the pairs.
  double max_interface_gap_mm = 0.0;
  double max_interface_slide_mm = 0.0;
  double seconds = 0.0;
  // Where the time went: local steps (projections), contact targets, the
  // global solves (right-hand sides and back-substitution), volume restoration.
  double local_seconds = 0.0;
  double contact_seconds = 0.0;
  double solve_seconds = 0.0;
  double volume_seconds = 0.0;
};

class TetSimulation {
 public:
  // `bones`: closed outward surfaces in the rest frame of the model, each
  // moved per frame by its pose. Throws InvalidInputError for an empty mesh,
  // an inverted or flat rest element, a driven node or bone index out of
  // range, a null or invalid bone surface, weights whose rows do not match
  // the meshes, or non-positive or non-finite weights / iterations.
  TetSimulation(EmbeddedModel model, std::vector<DrivenNode> driven,
                const std::vector<const mesh::IndexedMesh*>& bones,
                const SimulationOptions& options = {});
  // The elements are the output (embed_identity).
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

  // The output nodes after the last step (the rest before the first).
  [[nodiscard]] const Eigen::MatrixX3d& positions() const;
  // The element nodes after the last step.
  [[nodiscard]] const Eigen::MatrixX3d& element_positions() const;
  [[nodiscard]] const EmbeddedModel& model() const;
  // Output nodes checked against a bone (contact_reach_mm at rest).
  [[nodiscard]] int checked_nodes() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mmm::volumetric

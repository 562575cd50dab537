#pragma once
// Volume-preserving deformation of a closed muscle surface toward targets,
// with contacts: the energy-minimisation ("PK") step of muscle wrapping.
//
// Unknowns: the vertex positions x (#V by 3, mm). Energy
//
//   E(x) = |L x - D|^2 + w |x - T|^2 + c sum_{j in C} |x_j - y_j|^2
//
//   L  cotangent Laplacian of the rest surface (dimensionless, symmetric)
//   D  the rest Laplacian coordinates L X, each turned by its vertex's
//      rotation R_i: the surface keeps its local shape (detail) however the
//      skeleton turns it
//   T  targets: where the skeleton (action lines, bones) carries each vertex
//   w  tie weight, (h / l)^4 for the mean edge length h and the stiffness
//      length l: a push at one vertex spreads over about l
//   C  contacts: vertices that entered a bone, pinned (weight c) to a point
//      just outside it
//
// minimised subject to the hard constraint vol(x) = vol(X) (exact up to the
// tolerance, not a penalty). The matrix A = L^T L + w I depends on the rest
// mesh only: it is factored once (CHOLMOD) and every frame is
// back-substitution. Contacts change it by c E E^T (E selecting the contact
// vertices), applied exactly by the Woodbury identity: one solve per new
// contact, then a k by k dense system. The volume constraint is handled by
// Gauss-Newton on the Lagrangian: with g = d vol / dx at the current x,
//
//   x_new = u - lambda v,  u = A_C^-1 (L D + w T + c E Y),  v = A_C^-1 g,
//   lambda chosen so that vol(x) + <g, x_new - x> = vol(X),
//
// repeated until |vol - vol(X)| / vol(X) is below the tolerance (a few
// iterations: vol is cubic and v is a smooth, outward field).
//
// Contacts are found inside the iterations, not after them: after each solve
// the contact query reports vertices that now lie in a bone (with a point
// outside to pin them to); they join the active set and the volume-constrained
// problem is solved again, until no new vertex is inside. Because the volume
// is re-imposed with the contacts pinned, pushing a vertex out of a bone
// moves volume elsewhere instead of losing it.

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::wrapping {

struct DeformerOptions {
  double stiffness_length_mm = 15.0;  // > 0: how far a local push spreads
  double contact_weight = 1e4;        // > 0: pinning of contact vertices (dimensionless)
  double volume_tolerance = 1e-9;     // relative, > 0
  int max_volume_iterations = 30;     // >= 1
  int max_contact_rounds = 10;        // >= 1: solves with a grown contact set
};

// A vertex pinned to `target` (mm), outside the surface it entered.
struct Contact {
  int vertex = -1;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  int obstacle = -1;    // what it entered, for the caller (e.g. a bone index); not used here
  double weight = 0.0;  // > 0: its own pinning weight; 0: DeformerOptions::contact_weight
};

// Called with the current positions and a flag per vertex (1: already a
// contact); returns the vertices that must become contacts (not flagged
// ones). An empty answer ends the contact rounds.
using ContactQuery =
    std::function<std::vector<Contact>(const Eigen::MatrixX3d& x, const std::vector<char>& active)>;

struct DeformResult {
  Eigen::MatrixX3d x;             // #V by 3 (mm)
  double volume = 0.0;            // of x (mm^3)
  double volume_error = 0.0;      // (vol(x) - vol(X)) / vol(X)
  int volume_iterations = 0;      // Gauss-Newton steps, over all contact rounds
  int contact_rounds = 0;         // solves with a grown contact set (0: no contact)
  std::vector<Contact> contacts;  // the final contact set
  bool converged = true;          // volume within tolerance and contact query satisfied
};

class VolumeDeformer {
 public:
  // `rest`: closed, outward oriented surface with a positive volume. Builds
  // and factors A. Throws InvalidInputError on invalid indices or
  // coordinates, a non-positive volume or invalid options.
  VolumeDeformer(const mesh::IndexedMesh& rest, const DeformerOptions& options = {});
  ~VolumeDeformer();
  VolumeDeformer(VolumeDeformer&&) noexcept;
  VolumeDeformer& operator=(VolumeDeformer&&) noexcept;
  VolumeDeformer(const VolumeDeformer&) = delete;
  VolumeDeformer& operator=(const VolumeDeformer&) = delete;

  // targets    #V by 3 (mm), where the skeleton carries each vertex
  // rotations  #V rotations of the rest detail (empty: identity)
  // contacts   pinned from the start (e.g. the previous frame's, re-targeted)
  // query      finds new contacts after each solve (empty function: none)
  // Throws InvalidInputError on sizes that do not match or non-finite input.
  // Thread-safe (const): several frames or muscles may solve at once.
  [[nodiscard]] DeformResult solve(const Eigen::MatrixX3d& targets,
                                   const std::vector<Eigen::Matrix3d>& rotations,
                                   std::vector<Contact> contacts = {},
                                   const ContactQuery& query = {}) const;

  [[nodiscard]] const mesh::IndexedMesh& rest() const;
  [[nodiscard]] double rest_volume() const;
  [[nodiscard]] double tie_weight() const;  // w

  // The parts of the energy, for solving several surfaces together
  // (joint_deformer.h): A = L^T L + w I, and L D + w T for the given targets
  // and rotations (checked as by solve), so that E = x^T A x - 2 x . b + const.
  [[nodiscard]] const Eigen::SparseMatrix<double>& energy_matrix() const;
  [[nodiscard]] Eigen::MatrixX3d right_hand_side(
      const Eigen::MatrixX3d& targets, const std::vector<Eigen::Matrix3d>& rotations) const;
  [[nodiscard]] const DeformerOptions& options() const;

  struct State;  // the factored energy; defined in the .cpp only

 private:
  std::unique_ptr<State> state_;
};

// Signed volume of the surface x with faces F (mm^3), and its gradient
// (#V by 3): d vol / d x_i.
double enclosed_volume(const Eigen::MatrixX3d& x, const Eigen::MatrixX3i& F);
Eigen::MatrixX3d enclosed_volume_gradient(const Eigen::MatrixX3d& x, const Eigen::MatrixX3i& F);

}  // namespace mmm::wrapping

#pragma once
// Touching surfaces deformed together: the volume-preserving energy of
// volume_deformer.h for several closed surfaces ("bodies", the muscles of one
// pose) at once, coupled wherever one has entered another.
//
// Unknowns: every body's vertices, stacked. Energy
//
//   sum_m [ x_m^T A_m x_m - 2 x_m . b_m + c_m sum_{j in C_m} |x_j - y_j|^2 ]
//     + c sum_{(p, f, beta)} |x_p - (beta_1 x_i + beta_2 x_j + beta_3 x_k)|^2
//
//   A_m, b_m  body m's own energy in the pose (VolumeDeformer::energy_matrix
//             and right_hand_side: detail, targets)
//   C_m       its pins (bone contacts), as in volume_deformer.h
//   couplings a vertex p of one body found inside another is tied to the
//             nearest point of that body's surface, on its face f = (i, j, k)
//             at barycentric weights beta: that point moves with the other
//             body, so both sides give way in the same solve, each as far as
//             its own stiffness lets it (no share to choose).
//
// subject to vol(x_m) = vol(X_m) for every moved body (hard constraints: one
// Lagrange multiplier per body, Gauss-Newton: one solve per body's volume
// gradient, then a dense system the size of the group). A coupling acts alike
// on x, y and z, so each connected group of coupled bodies has one sparse
// matrix, factored once per round; bodies without coupling are not touched.
//
// Rounds: after each solve, new bone contacts (each body's query) and new
// entries of a vertex into another body are looked for on the current
// surfaces, and the groups that gained any are solved again, until none is
// found (then every vertex is outside the others, within the tolerance) or
// the rounds run out (the bodies with something left unsolved are reported
// unconverged). The first solve of a group frees all its vertices; later
// ones only those near what the round added (local_radius_mm), the rest
// held: what a few new entries change is local, and the volumes are still
// exact.

#include <vector>

#include "core/wrapping/muscle_penetration.h"
#include "core/wrapping/volume_deformer.h"

namespace mmm::wrapping {

struct JointBody {
  const VolumeDeformer* deformer = nullptr;  // its energy, faces and rest volume; not null
  Eigen::MatrixX3d right_hand_side;          // b_m in this pose
  Eigen::MatrixX3d start;                    // its positions before the joint solve (mm)
  std::vector<Contact> contacts;             // pinned throughout (bone contacts)
  ContactQuery query;                        // new bone contacts after each solve (may be empty)
};

struct JointOptions {
  MuscleContactOptions coupling;  // weight c, tolerance and reach of the entries (share unused)
  int max_rounds = 10;            // >= 1: solves with grown couplings or pins
  // After the first solve, a round frees only the vertices within this
  // distance (mm) of what it added, the rest held where they are (0: every
  // round solves the whole groups).
  double local_radius_mm = 30.0;
  int threads = 1;  // >= 1: queries and groups in parallel
};

struct JointResult {
  // Per body: x, volume, volume error, its pins (contacts), converged; a
  // body no coupling reached keeps its start.
  std::vector<DeformResult> bodies;
  std::vector<int> couplings;  // per body: its vertices tied to another body
  int rounds = 0;              // joint solves
  int largest_group = 0;       // bodies solved together, at most
  bool converged = true;       // every body: volume within tolerance, nothing left unsolved
};

// Throws InvalidInputError on a null deformer, sizes that do not match,
// non-finite input or invalid options.
JointResult solve_jointly(const std::vector<JointBody>& bodies, const JointOptions& options);

}  // namespace mmm::wrapping

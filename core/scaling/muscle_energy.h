#pragma once
// The energy that carries one muscle's surface onto the scaled skeleton
// (VPHOP D10.2, section 3.2): detail preservation, attachment/contiguity
// with the bones, and no new penetration of a bone.
//
// The starting shape X1 is the partition of unity of the bones' affine maps
// (patient_deformation.h: weights 1 / (d_b^2 + eps^2), d_b the distance to
// bone b at rest), which stretches a muscle smoothly with the segments it
// lies along. The muscle is then the displacement u = x - X1 minimising
//   E(u) = w_L |L u|^2                       keep X1's differential coordinates
//        + w_a sum_(i attached) |x_i - a_i|^2  contiguity: vertices touching a bone at
//                                             rest (within contact_distance_mm) stay
//                                             where that bone's scaled surface puts
//                                             them (affine anchors on the bone,
//                                             which follow its non-affine detail too)
//        + w_b sum_(i in band) |x_i - q_i|^2   vertices near a bone (band_mm): q_i = X1_i,
//                                             moved outward while x_i is deeper in the
//                                             bone than it was at rest
//        + w_d |u|^2                          gauge (tiny)
// Non-penetration: after each solve the band vertices are tested against
// every scaled bone they were near at rest (signed distance); any deeper than at rest
// (that depth scaled with the bone: the atlas's own overlaps are not new)
// plus a tolerance has its q_i moved out by its excess depth (+ a margin)
// along the direction to the bone surface, and the problem is solved again.
// Only band vertices are tested (a vertex farther than band_mm from a bone's
// surface at rest is out of its band, inside or not: a muscle 10 mm deep in
// a bone is a broken atlas, which atlas check reports). One farther than band_mm from every bone at
// rest would need the blend to move it that much more than the bone under
// it, far beyond the maps' differences near a joint in any human scaling.
// Every term's weights and vertex sets depend on the atlas alone, so the
// matrix w_L L^T L + W_a + W_b + w_d I is factored once per muscle in
// prepare_muscle (CHOLMOD, sparse_cholesky.h) and every patient and
// iteration is back-substitutions.

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/signed_distance.h"
#include "core/scaling/affine_anchor.h"
#include "core/scaling/sparse_cholesky.h"

namespace mmm::scaling {

struct MuscleEnergyOptions {
  double laplacian_weight = 1.0;     // w_L
  double attachment_weight = 10.0;   // w_a (per mm^2)
  double band_weight = 1.0;          // w_b (per mm^2)
  double gauge_weight = 1e-6;        // w_d, relative to the mean diagonal of w_L L^T L
  double contact_distance_mm = 1.5;  // attached: closer than this to a bone at rest
  double band_mm = 10.0;             // band: closer than this to a bone at rest
  double blend_radius_mm = 10.0;     // eps of the blend weights
  double penetration_tolerance_mm = 0.1;
  double penetration_margin_mm = 0.2;
  int max_penetration_iterations = 12;
};

// A bone as the muscles see it: rest surfaces for blend weights and contact.
struct BoneAtRest {
  std::string name;
  const mesh::IndexedMesh* full = nullptr;         // contact, attachment anchors
  const mesh::IndexedMesh* coarse = nullptr;       // blend distances (the coarsest level)
  const AnchorBuilder* anchors = nullptr;          // on `full`
  const mesh::SignedDistance* distance = nullptr;  // of `full`
};

// Everything about a muscle that does not depend on the patient.
struct PreparedMuscle {
  std::string name;
  Eigen::MatrixX3d rest;  // full-resolution vertices at rest
  Eigen::MatrixX3i faces;
  Eigen::MatrixXd blend;           // #V x #bones, rows sum to 1 (bones in the order given)
  std::vector<int> attached;       // vertex rows
  std::vector<int> attached_bone;  // index into the bones
  std::vector<AffineAnchor> attached_anchor;
  // Band: one entry per (vertex, bone) pair closer than band_mm at rest; a
  // vertex near two bones is tested against both.
  std::vector<int> band;  // vertex rows
  std::vector<int> band_bone;
  std::vector<double> band_rest_distance;  // signed distance at rest (mm; < 0 inside)
  double rest_volume_mm3 = 0.0;
  std::shared_ptr<SparseCholesky> factor;  // not shared between threads while solving
};

// Throws InvalidInputError for an invalid mesh, SolverError when the
// factorisation fails.
PreparedMuscle prepare_muscle(const std::string& name, const mesh::IndexedMesh& surface,
                              const std::vector<BoneAtRest>& bones,
                              const MuscleEnergyOptions& options = {});

// The scaled bones, in the order given to prepare_muscle.
struct ScaledBone {
  const Eigen::Affine3d* affine = nullptr;         // its affine part
  const Eigen::MatrixX3d* vertices = nullptr;      // its placed full surface
  const mesh::SignedDistance* distance = nullptr;  // of the placed full surface
};

struct MuscleSolution {
  Eigen::MatrixX3d vertices;
  double volume_ratio = 1.0;       // scaled / rest volume
  int penetration_iterations = 0;  // solves after the first
  // Band vertices deeper in their bone than at rest (by more than the
  // tolerance), and the largest such excess depth (mm), before and after.
  int penetrating_before = 0;
  double excess_depth_before_mm = 0.0;
  int penetrating_after = 0;
  double excess_depth_after_mm = 0.0;
  double attachment_rms_mm = 0.0;  // |x_i - a_i| over attached vertices
  int attached_vertices = 0;
  int band_vertices = 0;  // distinct vertices in the band
};

MuscleSolution solve_muscle(const PreparedMuscle& muscle, const std::vector<ScaledBone>& bones,
                            const MuscleEnergyOptions& options = {});

}  // namespace mmm::scaling

#pragma once
// The energy that places one bone's surface (VPHOP D10.2, section 3.2):
// Laplacian detail preservation (Sorkine 2006) with point terms, made
// invariant to the bone's affine map so that the proportions the landmarks
// call for cost nothing and only non-affine bending is paid for.
//
// The surface is written x = M (v - c) + t + d: an affine part g = (M, t)
// about the bone's centroid c, plus a detail displacement d per vertex.
// Point j is tied to the surface by an affine anchor a_j (affine_anchor.h)
// and pulled to its target p_j (landmarks, joint centres shared with the
// neighbouring bones) with weight w_j. Solved in two steps, so that the
// proportions the points call for cost nothing and only what no affine map
// explains is paid for as bending:
//  1. the affine part: least squares over the point terms, in the
//     directions of the 12 affine parameters they determine; the others keep
//     the first-stage estimate g0 (anatomical_scaling.h). In mm units (the
//     parameters of M weighed by the bone's RMS radius R), a direction is
//     determined when its eigenvalue of the points' normal matrix is at
//     least `determined_fraction` of the largest: the points are spread
//     along it by at least ~sqrt(fraction) R. So three landmarks fix the
//     9 parameters their plane allows and g0 fills the rest, and a pair of
//     points 1 mm apart (a landmark beside a joint centre) does not decide
//     how the whole bone shears. Exact for points an affine map explains;
//  2. the detail, when points are still missed: Laplacian detail
//     preservation (Sorkine 2006) of the affinely placed surface with the
//     point terms on the rest,
//       min w_L |L d|^2 + sum_j w_j |a_j . (x_affine + d) - p_j|^2 + w_d |d|^2,
//     L the cotangent Laplacian, w_d a tiny gauge: a smooth bend, one
//     sparse Cholesky factorisation shared by the three coordinates.
// Local points (falloff_radius_mm > 0: surface landmarks such as the
// epicondyles, malleoli or heel) stay out of step 1: the affine part follows
// what determines the whole bone (joint centres, the station's centres) and
// a local point moves only the part of the bone around it, through a
// compactly supported displacement field (local_field.h, radius R) fitted
// to its misfit after step 1, zero at the other points:
//  1b. x = x_affine + d_local(v), d_local = 0 beyond R of every local point.
// So two epicondyles widen the distal femur, not the shaft, and a heel
// placed 40 mm off drags the back of the calcaneus, not the whole foot.
// When g0 already meets every point term within closed_form_tolerance_mm
// nothing is solved (E = 0 there); when steps 1 and 1b meet them, no bend.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/scaling/affine_anchor.h"
#include "core/scaling/local_field.h"

namespace mmm::scaling {

struct BoneEnergyOptions {
  double laplacian_weight = 1.0;      // w_L
  double determined_fraction = 1e-3;  // see step 1
  double gauge_weight = 1e-4;         // w_d, relative to the mean diagonal of w_L L^T L
  double closed_form_tolerance_mm = 1e-6;
};

struct PointTerm {
  std::string name;  // for reports ("landmark asis_l", "joint knee_r")
  AffineAnchor anchor;
  Eigen::Vector3d rest = Eigen::Vector3d::Zero();    // the point on the rest surface (mm)
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // where it should go (mm)
  double weight = 1.0;                               // w_j (per mm^2)
  // > 0: a local point (step 1b), acting within this radius of its rest
  // position (mm); 0: it takes part in the bone's affine part.
  double falloff_radius_mm = 0.0;
};

struct BoneSolution {
  Eigen::MatrixX3d vertices;  // the placed surface
  Eigen::Affine3d affine;     // its affine part g, as a map of atlas points
  bool solved = false;        // false: closed form (g0 met every term)
  bool bent = false;          // true: step 2 ran (no affine map met every term)
  int free_directions = 0;    // affine parameter directions kept from g0 (of 4 per coordinate)
  // Step 1b's field (empty without local points), in the rest frame: the
  // placed surface is affine(v) + local.displacement(v) (+ the bend).
  LocalField local;
  // Per point term: |reconstructed point - target| (mm), in the given order.
  std::vector<double> residual_mm;
};

// Throws InvalidInputError for an invalid mesh or a non-finite target, and
// SolverError when the factorisation fails.
BoneSolution solve_bone(const mesh::IndexedMesh& rest, const Eigen::Affine3d& prior,
                        const std::vector<PointTerm>& terms, const BoneEnergyOptions& options = {});

}  // namespace mmm::scaling

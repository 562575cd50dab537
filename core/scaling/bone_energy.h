#pragma once
// The energy that places one bone's surface (VPHOP D10.2, section 3.2):
// Laplacian detail preservation (Sorkine 2006) with point terms, made
// invariant to the bone's affine map so that the proportions the landmarks
// call for cost nothing and only non-affine bending is paid for.
//
// The surface is written x = M (v - c) + t + d: an affine part g = (M, t)
// about the bone's centroid c, plus a detail displacement d per vertex. The
// differential coordinates of the result are asked to be those of the affine
// part (L x = L (V - c) M^T, i.e. L d = 0), so with L the cotangent Laplacian
//   E(d, g) = w_L |L d|^2                                   detail
//           + sum_j w_j |sum_i a_ji x_i - p_j|^2               point terms
//           + w_p |D (g - g0)|^2                             affine prior
//           + w_d |d|^2                                      gauge (tiny)
// where point j is tied to the surface by an affine anchor a_j
// (affine_anchor.h) and pulled to its target p_j (landmarks, joint centres
// shared with the neighbouring bones), g0 is the first-stage estimate
// (anatomical_scaling.h) and D = diag(R, R, R, 1) weighs the prior on M by
// the bone's RMS radius R, so both parts of the prior are in mm. When the
// point terms call for an affine map, the minimum is that map with d = 0
// (exactly, up to the prior's pull of ~w_p R^2 / w_j); when they cannot all
// be met by one affine map, d bends the surface smoothly around them.
//
// One linear least-squares problem per coordinate, all three sharing one
// matrix: the normal equations in d are factored once (sparse LDLT) and the
// four affine unknowns eliminated by their Schur complement (4 + 6 back
// substitutions in all). When g0 already meets every point term within
// `closed_form_tolerance_mm`, E(0, g0) = 0 is the minimum and nothing is
// solved.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/scaling/affine_anchor.h"

namespace mmm::scaling {

struct BoneEnergyOptions {
  double laplacian_weight = 1.0;        // w_L
  double affine_prior_weight = 1e-8;    // w_p (per mm^2)
  double gauge_weight = 1e-4;           // w_d, relative to the mean diagonal of w_L L^T L
  double closed_form_tolerance_mm = 1e-6;
};

struct PointTerm {
  std::string name;  // for reports ("landmark asis_l", "joint knee_r")
  AffineAnchor anchor;
  Eigen::Vector3d rest = Eigen::Vector3d::Zero();    // the point on the rest surface (mm)
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // where it should go (mm)
  double weight = 1.0;                               // w_j (per mm^2)
};

struct BoneSolution {
  Eigen::MatrixX3d vertices;  // the placed surface
  Eigen::Affine3d affine;     // its affine part g, as a map of atlas points
  bool solved = false;        // false: closed form (g0 met every term)
  // Per point term: |reconstructed point - target| (mm), in the given order.
  std::vector<double> residual_mm;
};

// Throws InvalidInputError for an invalid mesh or a non-finite target, and
// SolverError when the factorisation fails.
BoneSolution solve_bone(const mesh::IndexedMesh& rest, const Eigen::Affine3d& prior,
                        const std::vector<PointTerm>& terms, const BoneEnergyOptions& options = {});

}  // namespace mmm::scaling

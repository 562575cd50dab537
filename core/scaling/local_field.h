#pragma once
// A displacement field that acts near a few points and nowhere else: how a
// surface landmark (an epicondyle, a malleolus, the heel) moves the part of
// the bone it sits on without stretching the whole bone.
//
//   d(v) = sum_k phi(|v - p_k| / R_k) c_k,   phi(r) = (1 - r)^4 (4 r + 1) for r < 1, else 0
//
// phi is Wendland's C2 function (Wendland 1995, "Piecewise polynomial,
// positive definite and compactly supported radial functions of minimal
// degree"): smooth, 1 at the centre, 0 beyond R_k, and positive definite, so
// the interpolation below is well posed for distinct centres.
//
// Fitting: each local point j wants d(p_j) = r_j (the misfit it has left
// after the bone's affine part); each pinned point (a joint centre the
// affine part already meets) within reach of a local point wants d = 0 and
// becomes a centre too, so the field is exactly 0 there. One centre per
// condition: a square system, solved exactly. A point may be evaluated
// through samples (an affine anchor's vertices and weights, affine_anchor.h)
// so that its reconstruction on the displaced surface meets it exactly.
// Points are in the atlas's rest frame (mm): d is evaluated at rest
// positions and added to the placed surface.

#include <Eigen/Core>
#include <vector>

namespace mmm::scaling {

struct LocalField {
  std::vector<Eigen::Vector3d> centres;       // p_k, rest frame (mm)
  std::vector<double> radii_mm;               // R_k > 0
  std::vector<Eigen::Vector3d> coefficients;  // c_k (mm)

  [[nodiscard]] bool empty() const { return centres.empty(); }
  // d(v) (mm).
  [[nodiscard]] Eigen::Vector3d displacement(const Eigen::Vector3d& rest) const;
  // The Jacobian dd/dv at v (3 x 3, dimensionless).
  [[nodiscard]] Eigen::Matrix3d gradient(const Eigen::Vector3d& rest) const;
  // d at every row of V (#V by 3).
  [[nodiscard]] Eigen::MatrixX3d displacements(const Eigen::MatrixX3d& V) const;
};

// Wendland's C2 function of r = distance / radius.
double wendland_c2(double r);

struct LocalPoint {
  Eigen::Vector3d rest = Eigen::Vector3d::Zero();    // p_j, rest frame (mm)
  Eigen::Vector3d misfit = Eigen::Vector3d::Zero();  // r_j (mm); ignored for pins
  double radius_mm = 0.0;                            // R_j > 0: local; 0: pinned
  // d at the point is sum_i weights[i] d(samples[i]) when the samples stand
  // for the point (their field of a centre at the point is 1 within 20 %);
  // else (or empty) d(rest).
  std::vector<Eigen::Vector3d> samples;
  std::vector<double> weights;
};

// Fits the field (see the file comment): a centre at every local point and
// at every pinned point within the radius of one (with the largest local
// radius) and more than 1 mm from the other centres. Empty when no point is local. Throws
// InvalidInputError for a non-finite point, a negative radius or samples and weights of different
// sizes, SolverError when two conditions coincide (the system is singular).
LocalField fit_local_field(const std::vector<LocalPoint>& points);

}  // namespace mmm::scaling

#pragma once
// Registration of a generic bone model (OpenSim gait2392, metres, default
// pose) onto a subject's surfaces (the atlas frame, mm): the map that brings
// an OpenSim body, and everything attached to it (meshes, joint frames, path
// points, markers), into the atlas.
//
// The map is affine, x_atlas = A x_ground + t, found as
//   1. a start: the axis permutation between OpenSim's ground (X forward,
//      Y up, Z right) and the atlas (x right, y anterior, z superior), a
//      global scale and a translation (from the anchors when there are
//      any, else the centroids);
//   2. iterative closest points (Besl & McKay 1992) of the source vertices
//      onto the target surface, pairs farther than `trim_factor` times the
//      median distance rejected, plus weighted anchor pairs (e.g. the hip
//      centre onto the centre of the sphere fitted to the acetabular
//      cartilage), solved as a weighted similarity or rigid map (Umeyama
//      1991, fit/rigid_fit.h);
//   3. optionally, the same loop with a general affine map regularised
//      towards that similarity (Tikhonov on A - sR), so that the bone may
//      take the subject's proportions (lengths and widths) without shearing
//      wildly where the target surface says nothing.
//
// Residuals are reported in mm: the RMS of the accepted surface pairs and
// each anchor's distance after the fit.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/mesh/aabb_tree.h"

namespace mmm::atlas {

// A point that must land on a known position (both mm, the source already in
// the frame the start map produces — see register_points).
struct RegistrationAnchor {
  std::string name;
  Eigen::Vector3d source = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double weight = 1.0;  // relative to the whole set of surface pairs (1: as heavy as all of them)
};

struct RegistrationOptions {
  int similarity_iterations = 40;
  int affine_iterations = 30;
  bool anisotropic = true;
  // Keep the start's scale in the first phase (rigid steps): a similarity
  // ICP onto a surface can shrink the source towards a point of the target,
  // so surface-only fits take their scale from elsewhere (volume ratio).
  bool keep_scale = false;
  // Pairs farther than trim_factor * median distance (and than min_trim_mm)
  // are left out of each step.
  double trim_factor = 2.5;
  double min_trim_mm = 3.0;
  // Weight of || A - sR ||_F^2 against the mean squared pair distance per
  // unit of spread: larger keeps the map closer to a similarity.
  double affine_regularisation = 0.05;
  double tolerance_mm = 1e-4;  // stop when the RMS changes by less
};

struct RegistrationResult {
  Eigen::Affine3d map = Eigen::Affine3d::Identity();  // source (mm) -> target (mm)
  double scale = 1.0;                                 // cube root of det(A)
  double rms_mm = 0.0;                                // accepted surface pairs after the fit
  double mean_distance_mm = 0.0;
  int pairs = 0;  // accepted surface pairs at the end
  std::vector<std::pair<std::string, double>> anchor_residuals_mm;
};

// Registers the source points (#S by 3, mm) onto the target surface and the
// anchors. `start` is applied first (the result's map includes it). With no
// source points only the anchors count (at least 3 non-collinear, or 2 and a
// similarity is not determined: InvalidInputError). Throws InvalidInputError
// for non-finite input.
RegistrationResult register_points(const Eigen::MatrixX3d& source, const mesh::AabbTree* target,
                                   const std::vector<RegistrationAnchor>& anchors,
                                   const Eigen::Affine3d& start,
                                   const RegistrationOptions& options = {});

// The rotation nearest a linear map (polar decomposition, det +1).
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& linear);

}  // namespace mmm::atlas

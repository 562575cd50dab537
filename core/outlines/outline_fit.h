#pragma once
// One bone's surface fitted to its outlines on a calibrated radiograph pair:
// a silhouette-based 2D-3D fit (contour generator matched to image edges),
// with the scaled atlas's shape as the prior.
//
// Deformation model. The start surface X0 (the scaled atlas bone) moves by
//   x(X0) = X0 + D (X0 - c) + b + sum_i w_i(X0) t_i
// an affine change (D, b; c the centroid) plus a smooth displacement field of
// nodes t_i spread over the surface every `node_spacing_mm` (the centroids of
// the surface's vertices in a grid of that pitch); w_i are Gaussian weights
// (sigma = the spacing) over the `node_neighbours` nearest nodes, normalised
// to sum 1. x is linear in theta = (D, b, t), so the same map moves the
// coarse surface used for the contours, the full surface, and any point tied
// to the bone (landmarks, joint centres).
//
// Energy, minimised over theta by Gauss-Newton (the projection linearised at
// the current surface; contours and edges searched again every iteration):
//   E = sum_views sum_k h(r_k)                       contour terms
//     + w_pin   sum_p |x(P_p) - target_p|^2          operator's landmarks, joints
//     + w_corr  sum_c |proj(x(k_c)) - q_c|^2 s^2     operator's corrections
//     + w_s     sum_(i,j) |t_i - t_j|^2              smoothness (node graph)
//     + w_0 (sum_i |t_i|^2 + |b|^2) + w_A R^2 |D|_F^2   prior: stay near the start
// r_k = s * n_k . (proj(x_k) - q_k) in mm at the isocentre (s the pixel
// spacing): x_k a contour point of the current surface (contour_points.h),
// n_k its outward image normal, q_k the edge found along n_k
// (edge_image.h); h is the Huber loss (quadratic within robust_mm), done as
// iteratively reweighted least squares. Stages go coarse to fine: more image
// smoothing and a longer search first.
//
// A part of the bone that no contour reaches in either view keeps the
// prior's shape (smoothness carries its neighbours' motion); the result says
// how much of the surface that is.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/image/projection.h"
#include "core/mesh/mesh.h"
#include "core/outlines/edge_image.h"
#include "core/outlines/soft_tissue_model.h"
#include "core/outlines/thickness_term.h"

namespace mmm::outlines {

struct OutlineFitStage {
  double sigma_px = 1.0;  // image smoothing (an EdgeImage of this sigma must be given)
  double reach_mm = 4.0;  // edge search, each side of the current outline
  int iterations = 5;
  // Multiplies smoothness_weight in this stage: coarse stages, whose long
  // search can reach a neighbour's edges, hold the surface together more.
  double smoothness_factor = 1.0;
};

struct OutlineFitOptions {
  // Nodes closer than the bone is thick: a node field blends its nearest
  // nodes, and on a shaft thinner than about two spacings the nodes of
  // opposite sides cancel, so the shaft could not get thinner (measured:
  // 12 mm left a gait2392 femur 4.0 mm off, 6 mm 3.1 mm).
  double node_spacing_mm = 8.0;
  int node_neighbours = 4;
  // The two regularisers of the node field. Membrane (w_s, per node-graph
  // edge, scaled per stage): neighbouring nodes move alike; it also resists
  // a shaft's two sides moving apart or together, so it is kept weak in the
  // fine stages. Bending (w_b, per node): a node moves as the linear field of
  // its neighbours does; local widening, narrowing and shear are free, dents
  // and spikes are not. Measured on another person's bones (gait2392's): a
  // membrane of 0.5 alone left the femur at 3.5 mm, 0.1 -> 0.01 with bending
  // 2 at 0.9-1.6 mm.
  double smoothness_weight = 0.1;
  double bending_weight = 2.0;
  double prior_weight = 0.01;   // w_0
  double affine_weight = 0.05;  // w_A
  double pin_weight = 100.0;    // per mm^2
  double correction_weight = 10.0;
  // Image matches within this distance of an operator's correction point (mm
  // at the isocentre) are replaced by it: the operator overrides the image.
  double correction_radius_mm = 8.0;
  double robust_mm = 1.0;
  // An edge must fall at least this many times the image's median gradient.
  double min_fall_factor = 2.0;
  // Of two edges along the search the nearer is preferred: Gaussian weight
  // of sigma = nearness * reach on the distance.
  double nearness = 0.5;
  // Converged when no vertex moved more than this in the last iteration (mm).
  double converged_mm = 0.02;
  // The bone's brightness inside its outline (thickness_term.h); off unless
  // its weight is set.
  ThicknessOptions thickness;
  std::vector<OutlineFitStage> stages = {
      {3.0, 20.0, 6, 1.0}, {1.0, 4.0, 6, 0.2}, {1.0, 2.0, 6, 0.1}};
};

// A point tied to the bone that must stay or go somewhere (an operator's
// landmark on it, one of its joint centres).
struct PinnedPoint {
  std::string name;
  Eigen::Vector3d rest = Eigen::Vector3d::Zero();    // on or in the start surface (mm)
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // mm
  double weight = 1.0;                               // multiplies pin_weight
};

// An operator's correction: the bone's true edge passes through `pixel` in view
// `view` (index into the views).
struct CorrectionPoint {
  int view = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

// One view's edge images, one per stage sigma (same order as the stages).
struct FitView {
  const image::RadiographView* view = nullptr;
  std::vector<const EdgeImage*> edges;
  // Bones over each pixel at the start of the fit, for the thickness term
  // (bone_cover.h); null: no other bone is known.
  const std::vector<std::uint8_t>* cover = nullptr;
  // The soft tissue's predicted image, for the thickness term
  // (soft_tissue_model.h); null: a straight background across the bone.
  const SoftTissueImage* soft = nullptr;
};

struct BoneOutlineInput {
  std::string bone;
  const mesh::IndexedMesh* full = nullptr;  // the start surface, full resolution
  const mesh::IndexedMesh* work = nullptr;  // a coarser level of the same surface (contours)
  std::vector<PinnedPoint> pins;
  std::vector<CorrectionPoint> corrections;
};

struct ViewFit {
  std::string view;
  int contour_points = 0;      // of the work surface, at the end
  int matched = 0;             // with an edge found
  double start_mean_mm = 0.0;  // mean |r| of the first iteration's matches
  double mean_mm = 0.0;        // mean |r| at the end (matches of the last search)
  double p95_mm = 0.0;
  int corrections = 0;              // operator's points used
  double correction_mean_mm = 0.0;  // their mean distance to the fitted outline
  int thickness_samples = 0;        // of the last iteration with the thickness term
  double thickness_mean_mm = 0.0;   // their mean |r| (mm of bone along the ray)
  double thickness_gain = 0.0;      // image units per mm of bone
};

struct BoneOutlineFit {
  std::string bone;
  Eigen::MatrixX3d vertices;                              // the fitted full surface
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();   // I + D
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // as a map: x -> linear x + translation
  std::vector<ViewFit> views;
  double moved_mean_mm = 0.0;  // over the full surface's vertices
  double moved_max_mm = 0.0;
  double held_by_prior = 0.0;  // fraction of the full surface's vertices no contour reached
  bool converged = false;
  double last_change_mm = 0.0;      // largest vertex move of the last iteration
  double last_change_p95_mm = 0.0;  // its 95th percentile
  int iterations = 0;
  int nodes = 0;
  double seconds = 0.0;  // the fit's wall time
  // Pixels of each view (in order) where fitted neighbours were taken out of
  // the image the bone was fitted on; empty: none were.
  std::vector<int> neighbours_removed_px;
  std::vector<double> pin_residual_mm;  // per pin, in order
};

// Throws InvalidInputError for a missing or invalid mesh, work and full
// surfaces of different extent (not levels of one surface), a view index out
// of range, no stages, a FitView without an edge image per stage, or
// non-finite pins or corrections.
BoneOutlineFit fit_bone_outline(const BoneOutlineInput& input, const std::vector<FitView>& views,
                                const OutlineFitOptions& options = {});

}  // namespace mmm::outlines

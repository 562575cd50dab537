#pragma once
// The thickness term of the outline fit: the radiograph's brightness inside a
// bone's outline says how much bone each ray crosses, which the outlines
// alone do not (they fix where the surface turns away from the source, not
// where it lies between those turns: a tibial plateau's front may bulge or
// sink without moving either outline).
//
// Radiographs in mmm show attenuation, linear in the line integral of the
// attenuation coefficient along each ray. On a grid of sample pixels (every
// step_mm at the isocentre) over the bone's current projection, per image row:
//   background B(u): the image linearly interpolated between two points
//     margin_mm outside the current outline on either side (the soft tissue
//     around the bone); with a soft-tissue model S (soft_tissue_model.h),
//     S(u) plus the line through I - S at those points, so that the tissue
//     under the bone follows the limb's shape rather than a straight line
//   excess e = I(u, v) - B(u)            what the bone adds along the ray
//   gain g = sum e L / sum L^2           counts per mm of bone, estimated once
//                                        per view at the term's first use
//   residual r = e / g - L(theta)        mm of bone along the ray
// with L the length of the ray inside the current surface (entries and exits
// of the ray, in order). Moving the surface at a crossing by delta changes L
// by n . delta / |n . d| (n the face's unit normal, d the ray's direction),
// whichever side the crossing is on, so each sample gives one linear row:
//   sum_crossings (n / |n . d|) . x(theta) = sum (n / |n . d|) . x_cur + r.
// Rows are left out where the estimate cannot be trusted: another bone
// crosses the image row between the two background points (the bones'
// projections at the start of the fit, `cover`), a crossing is grazing
// (|n . d| < min_cosine: near the outline, where the contour terms act), or
// the background points fall outside the image.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/image/projection.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/mesh.h"
#include "core/outlines/bone_cover.h"
#include "core/outlines/edge_image.h"
#include "core/outlines/fit_rows.h"
#include "core/outlines/soft_tissue_model.h"

namespace mmm::outlines {

struct ThicknessOptions {
  double weight = 0.0;  // per sample, against 1 per contour point; 0: the term is off
  // The term's total weight in a view is at most max_share times its contour
  // points' (on real bone shapes weight 0.3 gives 0.5-1.8; on a coarse
  // surface with few contour points the rays would outweigh the outlines).
  double max_share = 2.0;
  int first_stage = 1;   // the stages from which it acts (after the outlines have settled)
  double step_mm = 2.0;  // sample grid pitch at the isocentre
  double margin_mm = 3.0;
  double min_cosine = 0.3;
  double robust_mm = 2.0;  // Huber threshold on r
  double cutoff = 3.0;     // samples with |r| beyond cutoff * robust_mm are left out
  // Estimate the gain again at every iteration (else once, at the first).
  bool refresh_gain = true;
};

struct ThicknessView {
  const image::RadiographView* view = nullptr;
  const EdgeImage* image = nullptr;                  // the radiograph, smoothed
  const std::vector<std::uint8_t>* cover = nullptr;  // bones over each pixel; null: none
  const BoneCover* own = nullptr;                    // this bone's part of `cover`
  // The soft tissue's predicted image (soft_tissue_model.h): the background
  // follows its shape between the two sides; null or unusable: a straight line.
  const SoftTissueImage* soft = nullptr;
};

struct ThicknessRows {
  std::vector<FitRow> rows;
  std::vector<double> residual_mm;  // |r| per row
};

// Rows of one view for the current surface, given as its tree (`tree`:
// same faces as the rest surface whose vertices are `rest`, with node weights
// `weights`; one tree serves both views). `gain` <= 0
// is estimated from the samples and written back; a positive one is used.
ThicknessRows thickness_rows(const mesh::AabbTree& tree, const Eigen::MatrixX3d& rest,
                             const NodeWeights& weights, const Eigen::Vector3d& centre,
                             const ThicknessView& view, const ThicknessOptions& options,
                             double& gain);

}  // namespace mmm::outlines

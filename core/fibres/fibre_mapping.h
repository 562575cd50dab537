#pragma once
// The steps the contour-based decompositions (slicing, harmonic) share:
// template fibres mapped through a stack of contours, fibre ends carried to
// their attachment areas, and fibres smoothed and resampled.

#include <Eigen/Core>
#include <vector>

#include "core/fibres/decomposition.h"
#include "core/fibres/fibre_set.h"
#include "core/fibres/fibre_templates.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

// Fibre f's point k is the mean-value image (contour_map.h) of template
// fibre f at s = k / (#contours - 1) in contour k. Contours: >= 2, one point
// count (a multiple of 8) for all.
std::vector<Fibre> fibres_through_contours(const std::vector<Contour>& contours,
                                           const std::vector<TemplateFibre>& templates);

// The plane in which fibre ends and attachment points are laid out to be
// matched: the muscle's cross-section (across axes.axis), for fibres that
// reach their ends through planar sections across the muscle (slicing,
// mass-spring); or the attachment area's own principal plane (its two
// directions of largest spread), for fibres that reach it through contours
// that hug the area (harmonic level sets).
enum class EndLayout { kCrossSection, kAttachmentPlane };

// Where each fibre end goes on an attachment area: `points` (the area's
// samples) and `ends` (#fibres by 3, where the fibres end before they are
// extended) are both laid out in the plane `layout`, and each coordinate is
// replaced by its rank over the count - 1 (so both spread evenly over
// [0, 1]^2 however they cluster); each end gets the index of the nearest
// point. So fibres keep their arrangement and their ends spread over the
// whole area.
std::vector<int> match_ends(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& ends,
                            const MuscleAxes& axes, EndLayout layout);

// The fibre with an extension at each end: a quadratic Bezier from the
// target to the fibre's end point, arriving along the fibre's own end
// direction, sampled at about the fibre's mean point spacing.
Fibre extend_fibre(const Fibre& fibre, const Eigen::Vector3d& origin_target,
                   const Eigen::Vector3d& insertion_target);

// A result holding `axes` and the contour stack of `values` at `levels`
// (contour_stack.h), started on the side of axes.reference.
ContourFibres contour_sections(const mesh::IndexedMesh& surface, const Eigen::VectorXd& values,
                               const std::vector<double>& levels, const MuscleAxes& axes,
                               int contour_points);

// result.fibres from the fibres `mapped` through result.contours: each end extended to the surface
// point nearest its own attachment point (match_ends on the mapped fibres' end points, in
// `layout`), smoothed (options.smoothing_passes), resampled to options.segments and kept inside
// `surface` (keep_inside.h, margin kInsideMarginMm; counted in
// result.moved_inside).
constexpr double kInsideMarginMm = 0.5;
void finish_fibres(ContourFibres& result, const mesh::IndexedMesh& surface,
                   const std::vector<Fibre>& mapped, const Attachments& attachments,
                   const DecompositionOptions& options, EndLayout layout);

// finish_fibres for the template of options.architecture (narrow end as
// attachments.narrow_at_insertion) mapped through result.contours.
void finish_template_fibres(ContourFibres& result, const mesh::IndexedMesh& surface,
                            const Attachments& attachments, const DecompositionOptions& options,
                            EndLayout layout);

// Each fibre connected at both ends to the nearest of the attachment points
// (the cadaver method's "connected to their nearest tendons"): extended
// (extend_fibre) from its end to the surface point nearest that attachment
// point, smoothed, resampled to `segments` and kept inside `surface`.
// Returns the number of points moved inside.
int connect_to_nearest_attachments(std::vector<Fibre>& fibres, const mesh::IndexedMesh& surface,
                                   const Attachments& attachments, int segments,
                                   int smoothing_passes);

// `passes` of Laplacian smoothing (each interior point moved half-way to
// the mean of its neighbours), ends fixed.
void smooth_fibre(Fibre& fibre, int passes);

// The polyline at segments + 1 points at equal arc-length steps, ends kept.
Fibre resample_fibre(const Fibre& fibre, int segments);

// Length of a polyline (mm).
double fibre_length(const Fibre& fibre);

}  // namespace mmm::fibres

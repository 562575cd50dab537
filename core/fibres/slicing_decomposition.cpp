#include "core/fibres/slicing_decomposition.h"

#include <algorithm>

#include "core/fibres/contour_stack.h"
#include "core/fibres/fibre_mapping.h"

namespace mmm::fibres {
namespace {

constexpr double kMinCut = 0.02;  // cut planes at least this fraction of the length in
constexpr double kMaxCut = 0.35;  // and at most this

}  // namespace

SlicingPlanes slicing_planes(const mesh::IndexedMesh& surface, const Attachments& attachments,
                             const MuscleAxes& axes, int segments) {
  SlicingPlanes planes;
  planes.vertex_heights = (surface.V.rowwise() - axes.origin_centre.transpose()) * axes.axis;
  const double lo = planes.vertex_heights.minCoeff();
  const double hi = planes.vertex_heights.maxCoeff();
  const double length = hi - lo;
  const double origin_cut = std::clamp(
      ((attachments.origin.rowwise() - axes.origin_centre.transpose()) * axes.axis).maxCoeff(),
      lo + kMinCut * length, lo + kMaxCut * length);
  const double insertion_cut = std::clamp(
      ((attachments.insertion.rowwise() - axes.origin_centre.transpose()) * axes.axis).minCoeff(),
      hi - kMaxCut * length, hi - kMinCut * length);
  for (int k = 0; k <= segments; ++k) {
    planes.levels.push_back(origin_cut + (insertion_cut - origin_cut) * k / segments);
  }
  return planes;
}

SlicingResult slicing_fibres(const mesh::IndexedMesh& surface, const Attachments& attachments,
                             const DecompositionOptions& options) {
  validate(options);
  SlicingResult result;
  result.axes = muscle_axes(surface, attachments);
  const SlicingPlanes planes = slicing_planes(surface, attachments, result.axes, options.segments);
  ContourStack stack = contour_stack(surface, planes.vertex_heights, planes.levels,
                                     result.axes.reference, options.contour_points);
  result.interpolated_contours = stack.interpolated;
  result.contours = std::move(stack.contours);
  const std::vector<TemplateFibre> templates =
      fibre_template(options.architecture, options.fibres, attachments.narrow_at_insertion());
  const mesh::AabbTree tree(surface);
  const mesh::WindingNumber inside(tree);
  result.fibres = finish_fibres(fibres_through_contours(result.contours, templates), templates,
                                attachments, result.axes, inside, options, &result.moved_inside);
  return result;
}

}  // namespace mmm::fibres

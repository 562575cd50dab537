#include "core/fibres/slicing_decomposition.h"

#include <algorithm>

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
  const MuscleAxes axes = muscle_axes(surface, attachments);
  const SlicingPlanes planes = slicing_planes(surface, attachments, axes, options.segments);
  SlicingResult result =
      contour_sections(surface, planes.vertex_heights, planes.levels, axes, options.contour_points);
  finish_template_fibres(result, surface, attachments, options, EndLayout::kCrossSection);
  return result;
}

}  // namespace mmm::fibres

#include "core/fibres/harmonic_decomposition.h"

#include <string>

#include "core/errors.h"
#include "core/fibres/contour_stack.h"
#include "core/fibres/fibre_mapping.h"
#include "core/fibres/fibre_templates.h"

namespace mmm::fibres {

HarmonicResult harmonic_fibres(const mesh::IndexedMesh& surface, const Attachments& attachments,
                               const Eigen::VectorXd& field, const DecompositionOptions& options) {
  validate(options);
  if (field.size() != surface.V.rows() || !field.allFinite()) {
    throw InvalidInputError("harmonic field: " + std::to_string(field.size()) +
                            " values for a surface of " + std::to_string(surface.V.rows()) +
                            " vertices, or a value that is not finite; recompute it for this mesh");
  }
  HarmonicResult result;
  result.axes = muscle_axes(surface, attachments);
  std::vector<double> levels;
  for (int k = 0; k <= options.segments; ++k) {
    levels.push_back(kHarmonicEndLevel + (1.0 - 2.0 * kHarmonicEndLevel) * k / options.segments);
  }
  ContourStack stack =
      contour_stack(surface, field, levels, result.axes.reference, options.contour_points);
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

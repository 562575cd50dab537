#include "core/fibres/harmonic_decomposition.h"

#include <string>

#include "core/errors.h"
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
  std::vector<double> levels;
  for (int k = 0; k <= options.segments; ++k) {
    levels.push_back(kHarmonicEndLevel + (1.0 - 2.0 * kHarmonicEndLevel) * k / options.segments);
  }
  HarmonicResult result = contour_sections(
      surface, field, levels, muscle_axes(surface, attachments), options.contour_points);
  const std::vector<TemplateFibre> templates =
      fibre_template(options.architecture, options.fibres, attachments.narrow_at_insertion());
  finish_fibres(result, surface, fibres_through_contours(result.contours, templates), attachments,
                options, EndLayout::kAttachmentPlane);
  return result;
}

}  // namespace mmm::fibres

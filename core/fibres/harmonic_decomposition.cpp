#include "core/fibres/harmonic_decomposition.h"

#include <string>

#include "core/errors.h"
#include "core/fibres/fibre_mapping.h"

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
  finish_template_fibres(result, surface, attachments, options, EndLayout::kAttachmentPlane);
  return result;
}

}  // namespace mmm::fibres

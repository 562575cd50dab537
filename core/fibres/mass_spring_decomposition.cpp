#include "core/fibres/mass_spring_decomposition.h"

#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/fibres/fibre_mapping.h"
#include "core/fibres/mass_spring.h"
#include "core/fibres/slicing_decomposition.h"

namespace mmm::fibres {

MassSpringDecomposition mass_spring_decomposition(const mesh::IndexedMesh& surface,
                                                  const Attachments& attachments,
                                                  const DecompositionOptions& options) {
  validate(options);
  if (options.fibres < 9) {
    throw InvalidInputError("mass-spring decomposition: " + std::to_string(options.fibres) +
                            " fibres asked for; the grid needs at least 3 x 3 = 9");
  }
  const MuscleAxes axes = muscle_axes(surface, attachments);
  const SlicingPlanes planes = slicing_planes(surface, attachments, axes, options.segments);
  MassSpringDecomposition result{contour_sections(surface, planes.vertex_heights, planes.levels,
                                                  axes, options.contour_points)};
  MassSpringOptions spring;
  spring.grid = static_cast<int>(std::lround(std::sqrt(static_cast<double>(options.fibres))));
  const MassSpringResult balanced = mass_spring_fibres(result.contours, spring);
  result.iterations = balanced.iterations;
  result.converged = balanced.converged;
  finish_fibres(result, surface, balanced.fibres, attachments, options, EndLayout::kCrossSection);
  return result;
}

}  // namespace mmm::fibres

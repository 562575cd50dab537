#include "core/fibres/mass_spring_decomposition.h"

#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/fibres/contour_stack.h"
#include "core/fibres/fibre_mapping.h"
#include "core/fibres/mass_spring.h"
#include "core/fibres/slicing_decomposition.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/winding_number.h"

namespace mmm::fibres {

MassSpringDecomposition mass_spring_decomposition(const mesh::IndexedMesh& surface,
                                                  const Attachments& attachments,
                                                  const DecompositionOptions& options) {
  validate(options);
  if (options.fibres < 9) {
    throw InvalidInputError("mass-spring decomposition: " + std::to_string(options.fibres) +
                            " fibres asked for; the grid needs at least 3 x 3 = 9");
  }
  MassSpringDecomposition result;
  result.axes = muscle_axes(surface, attachments);
  const SlicingPlanes planes = slicing_planes(surface, attachments, result.axes, options.segments);
  ContourStack stack = contour_stack(surface, planes.vertex_heights, planes.levels,
                                     result.axes.reference, options.contour_points);
  result.interpolated_contours = stack.interpolated;
  result.contours = std::move(stack.contours);
  MassSpringOptions spring;
  spring.grid = static_cast<int>(std::lround(std::sqrt(static_cast<double>(options.fibres))));
  const MassSpringResult balanced = mass_spring_fibres(result.contours, spring);
  result.iterations = balanced.iterations;
  result.converged = balanced.converged;
  // The grid's own templates, in its order (fibre (i, j) at i * grid + j).
  std::vector<TemplateFibre> templates;
  for (int i = 0; i < spring.grid; ++i) {
    for (int j = 0; j < spring.grid; ++j) {
      const Eigen::Vector2d at(static_cast<double>(i) / (spring.grid - 1),
                               static_cast<double>(j) / (spring.grid - 1));
      templates.push_back({at, {at, at, at}});
    }
  }
  const mesh::AabbTree tree(surface);
  const mesh::WindingNumber inside(tree);
  result.fibres = finish_fibres(balanced.fibres, templates, attachments, result.axes, inside,
                                options, &result.moved_inside);
  return result;
}

}  // namespace mmm::fibres

#pragma once
// The mass-spring decomposition (MMSS of the first reference document) of a
// muscle: the slicing method's planes (slicing_decomposition.h) give one
// contour per fibre level, a grid x grid mass-spring system balances inside
// them (mass_spring.h), and the fibre ends are carried to the attachment
// areas and kept inside as for the other methods (fibre_mapping.h). The
// fibres are parallel by construction: options.architecture is not used,
// and the fibre count is grid^2 with grid = round(sqrt(options.fibres)).

#include <vector>

#include "core/fibres/decomposition.h"
#include "core/fibres/fibre_set.h"

namespace mmm::fibres {

struct MassSpringDecomposition : ContourFibres {
  int iterations = 0;  // of the mass-spring balance
  bool converged = false;
};

// Throws InvalidInputError as slicing_fibres, and for fewer than 9 fibres.
MassSpringDecomposition mass_spring_decomposition(const mesh::IndexedMesh& surface,
                                                  const Attachments& attachments,
                                                  const DecompositionOptions& options = {});

}  // namespace mmm::fibres

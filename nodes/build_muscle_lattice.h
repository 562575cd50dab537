#pragma once
// Node `build_muscle_lattice`: the volumetric pathway's model at rest. Every
// muscle of the atlas in one labelled lattice, the bones carved out, the
// segmentations' overlaps resolved and the volume grown back
// (core/volumetric/labelled_lattice.h), then six tetrahedra per cell with the
// interfaces between touching muscles shared (lattice_tets.h). Built once per
// atlas and kept as a study artifact: the engine re-runs it only when the
// atlas or the parameters change.
//
//   input  atlas    Atlas   the (scaled) atlas
//   output lattice  File    folder bundle: lattice.json (grid, muscles in label
//                           order, per-muscle volumes, nodes and tetrahedra),
//                           muscles.lattice (the labels, lattice_io.h; the
//                           tetrahedra follow from them), muscles.vti (ParaView)
//   output report   Report  per muscle: segmented volume, what the grid, the
//                           bones and the other muscles changed, regrowth, kept

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct BuildMuscleLattice {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

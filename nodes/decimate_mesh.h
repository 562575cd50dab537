#pragma once
// Node `decimate_mesh`: a lower-resolution copy of a Mesh by quadric-error
// edge collapses (core/mesh/decimate.h).
//
//   input  mesh                  Mesh     surface to simplify (mm)
//   param  target_faces          integer  faces to reach (default 5000, >= 4)
//   param  max_normal_deviation  number   largest normal change per collapse,
//                                         deg (default 60, in [1, 180])
//   output decimated             Mesh     the simplified surface

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct DecimateMesh {
  static workflow::NodeSpec spec();
  // Throws InvalidInputError for a non-manifold input (repair it first).
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

#pragma once
// Node `build_hulls`: the progressive outer hull of every muscle's wrapping
// surface (core/wrapping/muscle_hulls.h), built once and kept as a study
// artifact: wrap_muscles reuses a hull whenever the surface it was built from
// has the same content hash, and the workflow engine re-runs this node only
// when the atlas or the parameters change.
//
//   input  atlas   Atlas   the (scaled) atlas
//   output hulls   File    folder bundle: hulls.json (per muscle: source hash,
//                          faces, volumes, containment check) + NAME.ply per muscle
//   output report  Report  per-muscle faces, volume added, containment, time

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct BuildHulls {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

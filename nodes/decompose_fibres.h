#pragma once
// Node `decompose_fibres`: every muscle's volume filled with fibres
// (core/fibres/muscle_fibres.h: slicing, harmonic, mass-spring or cadaver
// method, chosen for all muscles or per muscle), at rest, and in every frame
// of a wrapped motion when given one (the fibres follow the deformed muscle;
// the harmonic field is computed once per muscle).
//
//   input  atlas      Atlas   the (scaled) atlas
//   input  wrapped    MuscleFrames  optional: a wrapping node's wrapped motion
//                             (either pathway); each muscle is decomposed on its
//                             rest surface there, then in every stored frame with
//                             the attachments carried by the stored bone poses
//   output fibres     File    folder bundle: fibres.pvd + one .vtp of polylines per
//                             muscle and frame (ParaView plays them over the walk)
//   output lengths    File    CSV: muscle, method, fibre, frame, time, length (mm)
//   output picture    File    PNG: one muscle with its fibres, front and side views
//   output report     Report  per muscle: method, quality at rest, times

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct DecomposeFibres {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

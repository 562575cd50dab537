#pragma once
// Node `import_markups`: 3-D landmarks from a 3D Slicer Markups file
// (.mrk.json), an alternative to the landmark station when someone placed the
// points on a CT or MRI in Slicer (core/landmarks/slicer_markups.h: the
// file's coordinate system, LPS or RAS, and units are honoured; labels are
// matched to mmm's landmark names).
//
//   input  markups    File         the .mrk.json file
//   output landmarks  LandmarkSet  patient frame (RAS, mm), source "slicer_markups"

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct ImportMarkups {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

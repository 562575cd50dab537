#pragma once
// Node `import_markups`: 3-D landmarks from a 3D Slicer Markups file
// (.mrk.json), an alternative to the landmark station when someone placed the
// points on a CT or MRI in Slicer (core/landmarks/slicer_markups.h: the
// file's coordinate system, LPS or RAS, and units are honoured; labels are
// matched to mmm's landmark names through core/landmarks/landmark_labels.h;
// an unknown label is an error). The landmarks then pass the anatomical checks
// of landmark_validation.h (check_landmark_anatomy: heights, distances, sides,
// front-to-back order): a file whose coordinateSystem is wrong (x and y
// negated) fails with a hint instead of giving a model turned by 180 degrees.
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

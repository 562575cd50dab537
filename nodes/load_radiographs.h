#pragma once
// Node `load_radiographs`: a calibrated radiograph pair (RadiographPair) from
// the calibration sidecar (views.json, core/image/projection.h) and one PNG
// per view. The images are matched to the views by the view names "frontal"
// and "lateral" (a study keeps file contents, not file names).
//
//   input  calibration  File  the view sidecar (JSON: 3x4 matrices, sizes, spacing)
//   input  frontal      File  the frontal radiograph (grayscale PNG, 8 or 16 bit)
//   input  lateral      File  the lateral radiograph
//   output radiographs  RadiographPair  views + images, checked against each other

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct LoadRadiographs {
  static workflow::NodeSpec spec();
  // Throws IoError for an unreadable calibration or image, or an image whose
  // size is not its view's.
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

#pragma once
// Node `load_radiographs`: a calibrated radiograph pair (RadiographPair) from
// one image per view and their calibration. The images are matched to the
// views by the view names "frontal" and "lateral" (a study keeps file
// contents, not file names).
//
// An image is a grayscale PNG (8 or 16 bit) or a DICOM radiograph. A study
// never holds the DICOM file itself: at study creation it is replaced by its
// de-identified form (core/image/deidentified_radiograph.h, registered as a
// file importer in nodes/registry.cpp), which is what this node reads. The
// pair then carries each such image's display window and the hash of its
// SOP Instance UID.
//
// The calibration is the view sidecar (views.json) when given; without it,
// both images must be DICOM and their geometry attributes complete
// (core/image/dicom_views.h), with `model` saying whether the pair is a
// slot scan (EOS-type) or two conventional radiographs.
//
//   input  calibration  File  the view sidecar (optional with DICOM images)
//   input  frontal      File  the frontal radiograph (PNG or DICOM)
//   input  lateral      File  the lateral radiograph (PNG or DICOM)
//   param  model        pinhole | slot-scanning (calibration from DICOM only)
//   output radiographs  RadiographPair  views + images, checked against each other

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct LoadRadiographs {
  static workflow::NodeSpec spec();
  // Throws IoError for an unreadable calibration or image, an image whose
  // size is not its view's, or DICOM geometry too incomplete to calibrate
  // from (naming the file and the attribute).
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

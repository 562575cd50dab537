#pragma once
// Node `landmark_report`: what a landmark set says about the patient, for
// people and for the checks downstream: every landmark's position, the
// distances along the leg (femoral head -> patella -> ankle centres) and the
// triangulation's reprojection errors.
//
//   input  landmarks  LandmarkSet
//   output report     Report  {"frame", "source", "landmarks": {NAME: [x, y, z]},
//                              "distances_mm": {"A-B": d}, "reprojection_error_mm":
//                              {"max": e, "mean": e}}

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct LandmarkReport {
  static workflow::NodeSpec spec();
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes

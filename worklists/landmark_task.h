#pragma once
// The landmark station: the manual node `landmark_station` and what its tasks
// ask for and do with a submission.
//
//   input  radiographs                RadiographPair  the patient's calibrated pair
//   input  patient (optional)         String  patient identifier shown to the operator
//   param  require_ankle              bool    ankle centre required (default false:
//                                             optional)
//   param  reprojection_tolerance_mm  number  largest accepted reprojection error
//                                             per view (default 3 mm, see
//                                             core/landmarks/landmark_validation.h)
//   param  side                       enum    right | left: the leg (default right)
//   param  review                     bool    a second operator accepts each
//                                             submission (default false)
//   param  instructions               string  shown to the operator
//   output landmarks                  LandmarkSet  triangulated points (patient frame, mm)
//
// A task's request (what the operator sees and the web page draws):
//   {"kind": "landmarks", "instructions": "...",
//    "landmarks": [{"name": "femoral_head_centre_r", "label": "...", "required": true,
//                   "hint": "..."}, ...],
//    "views": [{"name": "frontal", "width": 970, "height": 2839,
//               "pixel_spacing_mm": 0.38, "P": [[...], [...], [...]],
//               "image_sha256": "..."}, ...],
//    "images": {"frontal": "<sha256>", "lateral": "<sha256>"},
//    "radiographs": "<artifact hash>", "patient": "P001",
//    "reprojection_tolerance_mm": 3, "side": "right", "review": false}
// A submission gives each landmark's pixel position in each view:
//   {"landmarks": {"femoral_head_centre_r": {"frontal": [u, v], "lateral": [u, v]}, ...}}
// Anything malformed in it is a reason to reject, never an exception.
// The node type carries this as its task behaviour (workflow/manual_task.h).

#include <nlohmann/json.hpp>

#include "workflow/manual_task.h"
#include "workflow/node_context.h"
#include "workflow/node_spec.h"
#include "workflow/store/artifact_store.h"
#include "workflow/study/cache_key.h"
#include "worklists/manual_evaluation.h"

namespace mmm::worklists {

inline constexpr const char* kLandmarkStationType = "landmark_station";

struct LandmarkStation {
  static workflow::NodeSpec spec();
  // Never called by the engine (the node is manual); throws to say so.
  static void run(workflow::NodeContext& context);
  // Its tasks: landmark_task_request, evaluate_landmark_submission.
  static workflow::ManualTaskBehaviour task_behaviour();
};

// The request of a task opened for a landmark_station node with these key
// parts (parameters, input hashes); reads the radiograph pair artifact.
nlohmann::json landmark_task_request(const workflow::CacheKeyParts& parts,
                                     const workflow::ArtifactStore& artifacts);

// Triangulates and validates a submission against the task's request.
ManualEvaluation evaluate_landmark_submission(const nlohmann::json& request,
                                              const nlohmann::json& submission);

}  // namespace mmm::worklists

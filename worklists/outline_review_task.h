#pragma once
// The outline review station: the manual node `outline_review`, where an
// operator checks the outlines of the atlas bones fitted to a patient's
// radiographs (projected silhouettes, core/image/silhouette.h) and accepts
// them or marks where the true edges lie.
//
//   input  radiographs         RadiographPair  the patient's calibrated pair
//   input  atlas               Atlas   the bones fitted to the radiographs
//   input  patient (optional)  String  patient identifier shown to the operator
//   param  review              bool    a second operator accepts each
//                                      submission (default false)
//   param  instructions        string  shown to the operator
//   param  level               string  the atlas mesh level outlined (default lod1)
//   output corrections         OutlineCorrections  the verdict
//                                      (core/image/outline_corrections.h)
//
// A task's request (what the operator sees and the web page draws):
//   {"kind": "outline_review", "instructions": "...", "review": false,
//    "level": "lod1", "patient": "P001",
//    "radiographs": "<artifact hash>", "atlas": "<artifact hash>",
//    "views": [...], "images": {...}          as the landmark station's
//    "bones": [{"name": "femur_r", "colour": "#ff4040",
//               "outlines": {"frontal": [[[u, v], ...], ...], "lateral": [...]}}, ...],
//    "limits": {"points_per_correction": 200, "points": 2000}}
// outlines: per view, the bone's silhouette as polylines (pixels, 0.1 px).
// A submission accepts the outlines or corrects them:
//   {"decision": "accept"}
//   {"decision": "correct",
//    "corrections": [{"bone": "femur_r", "view": "frontal", "points": [[u, v], ...]}, ...]}
// points: where the bone's true edge lies in that view (pixels, inside the
// image), 1-200 per (bone, view), 2000 in all, each (bone, view) once.
// Anything malformed is a reason to reject, never an exception. The accepted
// value is the canonical OutlineCorrections text (sorted by bone, then view),
// so the same submission always gives the same artifact.

#include <nlohmann/json.hpp>

#include "workflow/manual_task.h"
#include "workflow/node_context.h"
#include "workflow/node_spec.h"
#include "workflow/store/artifact_store.h"
#include "workflow/study/cache_key.h"

namespace mmm::worklists {

struct OutlineReviewStation {
  static workflow::NodeSpec spec();
  // Never called by the engine (the node is manual); throws to say so.
  static void run(workflow::NodeContext& context);
  // Its tasks: outline_review_request, evaluate_outline_review.
  static workflow::ManualTaskBehaviour task_behaviour();
};

// The request of a task opened for an outline_review node with these key
// parts; reads the radiograph pair and the atlas (its meshes at `level`).
// Throws InvalidInputError when an input is missing or a bone has no mesh
// at that level (the levels it has are named).
nlohmann::json outline_review_request(const workflow::CacheKeyParts& parts,
                                      const workflow::ArtifactStore& artifacts);

// Checks a submission against the task's request; accepted: the
// OutlineCorrections text as output "corrections", its JSON as values.
workflow::ManualEvaluation evaluate_outline_review(const nlohmann::json& request,
                                                   const nlohmann::json& submission);

}  // namespace mmm::worklists

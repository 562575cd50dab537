#pragma once
// Every chosen bone of a (scaled) atlas fitted to its outlines on the
// patient's calibrated radiograph pair (outline_fit.h), with the operator's
// landmarks on a bone as strong pins, the bone's joint centres as weaker ones
// (the chain stays connected) and the operator's contour corrections, if any.
// Bones not chosen keep their shape.
//
// The images are smoothed once per view and stage sigma; bones are fitted in
// parallel (each fit is independent: a bone's outline is matched to the
// image, never to another bone's fitted outline).

#include <map>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_meshes.h"
#include "core/image/radiograph_pair.h"
#include "core/landmarks/landmark_set.h"
#include "core/outlines/outline_fit.h"

namespace mmm::outlines {

struct AtlasOutlineFitOptions {
  OutlineFitOptions fit;
  // Bones fitted. The default: the hip bones, sacrum and the leg's long
  // bones. The foot's small bones overlap each other in the lateral view, and
  // the patella's outline lies on the femur's in the frontal one: fitted, it
  // came out worse than scaled on every kind of test patient (1.0 -> 1.4 mm
  // in the demo study), so they keep the scaling's shape unless asked for.
  std::vector<std::string> bones = {"pelvis",  "pelvis_l", "sacrum",
                                    "femur_r", "tibia_r",  "fibula_r"};
  // Per bone, a factor on the fit's membrane weight. The hip bones' and the
  // sacrum's outlines cross many edges of their own (the iliac wings seen
  // edge-on, the obturator foramen, the sacral foramina) and of their
  // neighbours; a stiffer membrane keeps them from following those, where
  // the long bones need a weak one to narrow between their outlines
  // (measured on another person's hip bone: 2.83 -> 3.06 mm, on the atlas
  // with local shape 0.15-0.34 -> 0.08-0.09 mm). Bones the atlas lacks are
  // ignored.
  std::map<std::string, double> membrane_factor = {
      {"pelvis", 3.0}, {"pelvis_l", 3.0}, {"sacrum", 3.0}};
  std::string work_level = "lod1";  // contours are found on this level
  double landmark_pin = 1.0;        // pin weight factor of an operator's landmark
  double joint_pin = 0.1;           // of a joint centre
  int threads = 2;
};

// An operator's correction points of one bone in one view (pixels).
struct OutlineCorrection {
  std::string bone;
  std::string view;
  std::vector<Eigen::Vector2d> points_px;
};

struct AtlasOutlineFit {
  std::vector<BoneOutlineFit> bones;    // in the order of options.bones present in the atlas
  std::vector<std::string> not_fitted;  // bones of the atlas kept as they were
  double images_seconds = 0.0;
  double fit_seconds = 0.0;
};

// Throws InvalidInputError for a bone asked for that the atlas lacks (listing
// its bones), a correction naming an unknown bone or view, a membrane factor
// that is not a positive number, or what
// fit_bone_outline throws.
AtlasOutlineFit fit_atlas_outlines(const atlas::Atlas& atlas, const atlas::AtlasMeshes& meshes,
                                   const landmarks::LandmarkSet& landmarks,
                                   const image::RadiographPair& pair,
                                   const std::vector<OutlineCorrection>& corrections,
                                   const AtlasOutlineFitOptions& options = {});

}  // namespace mmm::outlines

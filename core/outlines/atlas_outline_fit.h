#pragma once
// Every chosen bone of a (scaled) atlas fitted to its outlines on the
// patient's calibrated radiograph pair (outline_fit.h), with the operator's
// landmarks on a bone as strong pins, the bone's joint centres as weaker ones
// (the chain stays connected) and the operator's contour corrections, if any.
// Bones not chosen keep their shape.
//
// The images are smoothed once per view and stage sigma; bones are fitted in
// parallel, in rounds (AtlasOutlineFitOptions::rounds): first on the
// radiographs, then on the radiographs with the other bones' latest fits
// taken out (neighbour_layers.h). A bone's outline is matched to an
// image, never to another bone's fitted outline.

#include <map>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_meshes.h"
#include "core/image/radiograph_pair.h"
#include "core/landmarks/landmark_set.h"
#include "core/outlines/outline_fit.h"

namespace mmm::outlines {

// The single-bone fit's options with the thickness term on (weight 0.3 per
// ray): with the soft tissue modelled (below), it takes another person's
// tibia from 2.27 to 1.55 mm and femur from 1.25 to 1.08 (medians of six).
inline OutlineFitOptions whole_leg_fit_options() {
  OutlineFitOptions options;
  options.thickness.weight = 0.3;
  return options;
}

struct AtlasOutlineFitOptions {
  OutlineFitOptions fit = whole_leg_fit_options();
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
  // Predict the soft tissue's image from the atlas's muscles
  // (soft_tissue_model.h): the thickness term's background follows the
  // limb's shape under each bone, and tissue_free_bones are fitted without
  // it. Off: a straight background, and every bone on the radiographs as
  // they are.
  bool soft_tissue_model = true;
  SoftTissueModelOptions soft_tissue;
  // Bones whose outlines are sought on the radiographs with the modelled soft
  // tissue taken out (without_soft_tissue; needs soft_tissue_model). The hip
  // bones and sacrum: in the trunk the tissue's thickness changes fast and
  // its slopes move their edges (measured on another person's hip bone:
  // 3.16 -> 2.88 mm, median of six; the atlas patients' unchanged). The long
  // bones' outlines are better on the radiographs as they are (another
  // person's tibia 1.52 and 1.34 -> 1.90 and 1.46 mm without the tissue).
  std::vector<std::string> tissue_free_bones = {"pelvis", "pelvis_l", "sacrum"};
  // Per bone, a factor on the thickness term's weight (bones not listed: 1).
  // Off for the hip bones and sacrum: their rows cross each other in the
  // lateral view and the trunk's tissue in the frontal one; measured, the
  // term moved another person's hip bone 3.16 -> 3.02 mm and cost the atlas
  // patients' 0.08-0.49 -> 0.54-0.63.
  std::map<std::string, double> thickness_factor = {
      {"pelvis", 0.0}, {"pelvis_l", 0.0}, {"sacrum", 0.0}};
  // Per bone, the node spacing of its displacement field (mm; bones not
  // listed: fit.node_spacing_mm).
  std::map<std::string, double> node_spacing_mm = {};
  // The fit's rounds, in order; "*" stands for every fitted bone that no
  // round names, and bones no round names are fitted first. A round's bones
  // are fitted (again, from the start surface) on radiographs from which
  // every other bone's latest fit is taken out (neighbour_layers.h), each at
  // the gain its thickness term measured: their outlines no longer run
  // across a neighbour's edges, and the thickness term reads them on rows a
  // neighbour crosses. Needs the thickness term; without it every bone is
  // fitted once. Bones not fitted (or not in the atlas) are ignored. The
  // default fits the fibula after the rest: in the frontal view it lies over
  // the tibia, and with the tibia taken out another person's fibula came
  // 2.62 -> 1.11 mm. Taking the fibula out of the tibia's images, or the
  // sacrum and other hip bone out of the hip bone's, did not help: the
  // neighbours' fits and gains are not good enough for that.
  std::vector<std::vector<std::string>> rounds = {{"*"}, {"fibula_r"}};
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

// The soft tissue's law fitted on one view (soft_tissue_model.h).
struct SoftTissueLaw {
  std::string view;
  bool used = false;  // fitted and used by the thickness term
  double offset = 0.0;
  double tissue_per_mm = 0.0;
  double muscle_per_mm = 0.0;
  int samples = 0;
  double residual_rms = 0.0;
  int rows_matched = 0;  // rows whose limb outline was fitted to the image's
  double median_width_ratio = 1.0;
};

struct AtlasOutlineFit {
  std::vector<BoneOutlineFit> bones;       // in the order of options.bones present in the atlas
  std::vector<SoftTissueLaw> soft_tissue;  // per view, when the model was built
  std::vector<std::string> not_fitted;     // bones of the atlas kept as they were
  double images_seconds = 0.0;
  double fit_seconds = 0.0;  // both rounds, with the neighbours' layers
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

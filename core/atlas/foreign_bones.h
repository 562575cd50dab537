#pragma once
// Bones of another person: OpenSim gait2392's bone geometry (a different
// skeleton from the atlas's Visible Human Female) placed where the atlas's
// bones are, then given a synthetic patient's proportions. A patient made of
// these cannot be represented exactly by any smooth map of the atlas, which
// is what an honest accuracy test of scaling and outline fitting needs.
//
// Per bone (gait2392 file -> atlas bone: pelvis, l_pelvis -> pelvis_l,
// sacrum, femur_r, patella_r, tibia_r, fibula -> fibula_r, talus -> talus_r,
// foot -> calcn_r (calcaneus and midfoot in one surface), bofoot -> toes_r):
//  1. the body-frame surface (m) into the atlas by the atlas bone's frame
//     (the gait2392 body frame the atlas was built with), at the scale that
//     makes it as long as the atlas bone (the longest side of the oriented
//     bounding box), so that the joints meet as in the atlas; the foot bones
//     take the tibia's scale;
//  2. for the bones that are one bone in both (not the foot), a rigid
//     iterative-closest-point refinement onto the atlas bone at that scale;
//  3. the patient deformation of `deformation` (patient_deformation.h: the
//     stature, segment lengths and widths, pelvis width, neck-shaft angle
//     and local shape of a synthetic patient) on top.
// The soft tissue is the atlas's muscles at `muscle_level` under the same
// deformation.

#include <filesystem>
#include <string>

#include "core/atlas/bone_set.h"
#include "core/atlas/patient_deformation.h"

namespace mmm::atlas {

struct ForeignBoneOptions {
  PatientOptions deformation;
  std::string muscle_level = "lod1";
  int threads = 2;
};

// Throws IoError naming the file for unreadable gait2392 geometry (under
// data_dir/gait2392/Geometry) or atlas.
BoneSet gait2392_bone_set(const std::filesystem::path& atlas_dir,
                          const std::filesystem::path& data_dir, const ForeignBoneOptions& options);

}  // namespace mmm::atlas

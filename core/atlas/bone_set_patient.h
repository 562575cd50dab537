#pragma once
// A patient folder made from a bone set (bone_set.h): bones from CT or from
// another model, not the atlas deformed, so that landmark scaling and outline
// fitting can be measured on anatomy the atlas cannot represent exactly.
//
// Folder written (`mmm patient from-bones MANIFEST --atlas ATLAS -o PDIR`),
// the layout of `mmm patient synth` where it applies:
//   bones/<bone>.ply          the true surfaces (patient frame, mm); a bone
//                             given as a broken surface (holes, non-manifold
//                             edges, several pieces) as the boundary of the
//                             solid it encloses (mesh/solidify.h, 1 mm grid,
//                             simplified to 40,000 faces),
//                             which is what the radiographs show
//   ground_truth.json         {"format": "mmm-bone-set-patient", "version": 1,
//                              "atlas", "source", "bones": [...],
//                              "solidified": [bones rebuilt so],
//                              "landmarks": {name: {"bone", "position_mm",
//                              "pixels": {view: [u, v]}, "from": "given" |
//                              "<how it was derived>"}}}
//   radiographs/              the calibrated pair (patient_radiographs.h)
//
// Landmarks the set does not give are derived for every atlas landmark on a
// bone of the set: the atlas bone is registered onto the given bone (rigid
// with the volume ratio's scale, then an affine refinement), the atlas point
// mapped, and then, by the landmark's definition:
//   femoral head centre   centre of the sphere fitted to the given femur's
//                         vertices within 1.25 head radii of the mapped
//                         centre (twice, re-centred)
//   patella centre        centroid of the given patella's volume
//   tagged "bony"         the given surface's point nearest the mapped one
//   otherwise (joint centres) the mapped point
// Each landmark records how it was obtained ("from").

#include <filesystem>
#include <string>
#include <vector>

#include "core/atlas/bone_set.h"
#include "core/atlas/patient_radiographs.h"

namespace mmm::atlas {

inline constexpr double kSolidifyGridMm = 1.0;
inline constexpr Eigen::Index kSolidifiedFaces = 40000;  // a rebuilt bone simplified to

struct BoneSetPatientReport {
  int bones = 0;
  std::vector<std::string> solidified;  // bones given as broken surfaces, rebuilt closed
  int landmarks_given = 0;
  int landmarks_derived = 0;
  int frontal_width = 0;
  int frontal_height = 0;
  double pixel_spacing_mm = 0.0;
  double seconds = 0.0;
};

// Writes the folder `out_dir` (replaced only once complete). Throws
// InvalidInputError for a bone of the set the atlas does not have (listing the
// atlas's bones) or options out of range, IoError for an unreadable atlas or
// an unwritable folder.
BoneSetPatientReport make_bone_set_patient(const BoneSet& set,
                                           const std::filesystem::path& atlas_dir,
                                           const std::filesystem::path& out_dir,
                                           const PatientRadiographOptions& options);

}  // namespace mmm::atlas

#pragma once
// A set of bone surfaces from any source (CT segmentations, another model's
// geometry) described by a small YAML manifest, so that a patient folder can
// be made from them (bone_set_patient.h) and the atlas fitted against bones it
// was not built from.
//
//   mmm_bone_set: 1
//   units: mm                 # mm | m: the files' length unit
//   frame: RAS                # RAS (x right, y anterior, z superior) | LPS
//                             # (x left, y posterior, z superior: DICOM);
//                             # converted to mmm's RAS patient frame
//   transform:                # optional 4 x 4 row-major (after units and
//     [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]   # frame): files -> patient
//   bones:                    # atlas bone name -> surface file (relative to
//     femur_r: femur.ply      # the manifest; STL, OBJ, PLY, OFF, VTP)
//     tibia_r: tibia.stl
//   soft_tissue: [thigh.ply]  # optional closed surfaces rendered as soft tissue
//   landmarks:                # optional, same units and frame as the files
//     femoral_head_centre_r: [x, y, z]
//
// Every file is read whole only after its size is checked (1 GiB), every
// field is checked, and an error names the manifest and the field with a
// hint.

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::atlas {

struct BoneSet {
  std::map<std::string, mesh::IndexedMesh> bones;    // patient frame (RAS), mm
  std::vector<mesh::IndexedMesh> soft_tissue;        // patient frame, mm
  std::map<std::string, Eigen::Vector3d> landmarks;  // patient frame, mm
  std::string source;                                // where it came from (for provenance)
};

// Throws IoError naming the manifest (and field) for a missing, malformed or
// oversized manifest or surface, InvalidInputError for an empty bone list, a
// non-finite number or a transform that is not a proper rigid-or-affine map
// (bottom row other than 0 0 0 1, singular linear part).
BoneSet read_bone_set(const std::filesystem::path& manifest);

// Writes the set as PLY files plus manifest.yaml (mm, RAS, no transform)
// under `dir`; read_bone_set(dir / "manifest.yaml") reads it back.
void write_bone_set(const BoneSet& set, const std::filesystem::path& dir);

}  // namespace mmm::atlas

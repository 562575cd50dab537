#pragma once
// A small leg atlas with meshes for tests of atlas scaling: pelvis -hip->
// femur_r -knee-> tibia_r -ankle-> talus_r, the patella welded to the tibia
// (as in the default atlas), ellipsoid surfaces at two levels of detail
// ("full", "lod1"), the station's three landmarks plus a lateral epicondyle
// and both ASIS,
// a thigh marker, and a muscle along the femur (2 mm into it, as atlas
// segmentations overlap) with an action line, an attachment area and a wrap
// obstacle; a cartilage on the distal femur and a ligament across the knee
// from the femur to the tibia.

#include <Eigen/Core>
#include <filesystem>

#include "core/atlas/atlas.h"
#include "core/atlas/atlas_meshes.h"
#include "core/mesh/mesh.h"

namespace mmm::test {

struct ToyLeg {
  atlas::Atlas atlas;
  atlas::AtlasMeshes meshes;
};

// An ellipsoid of semi-axes `radii` centred at `centre` (an icosphere of
// `subdivisions`, stretched).
mesh::IndexedMesh ellipsoid(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii,
                            int subdivisions = 3);

ToyLeg toy_leg();

// Writes the toy leg as an atlas folder (atlas.yaml + meshes).
void write_toy_leg(const std::filesystem::path& dir);

}  // namespace mmm::test

#pragma once
// A muscle's attachment areas in the atlas (bone faces) turned into the
// point samples the decomposition methods take, at rest or carried by the
// bones of a posed frame.

#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/fibres/decomposition.h"
#include "core/mesh/mesh.h"

namespace mmm::fibres {

// The samples of one attachment area: the centroid and the corners of each
// of its bone faces (rest pose, atlas frame, mm).
struct AreaSamples {
  std::string bone;
  Eigen::MatrixX3d points;
  double area_mm2 = 0.0;
};

struct MuscleAttachmentSamples {
  std::vector<AreaSamples> origin;
  std::vector<AreaSamples> insertion;
};

// `bone_surface(name)` returns the full-resolution surface the areas' face
// indices refer to. Throws InvalidInputError when the muscle has no origin
// or no insertion area, or a face index is out of range.
MuscleAttachmentSamples attachment_samples(
    const atlas::Muscle& muscle,
    const std::function<const mesh::IndexedMesh&(const std::string&)>& bone_surface);

// The samples as Attachments, each area's points moved by `pose(bone)` (the
// bone's rest -> current transform; identity at rest).
Attachments posed_attachments(
    const MuscleAttachmentSamples& samples,
    const std::function<Eigen::Isometry3d(const std::string&)>& pose = {});

}  // namespace mmm::fibres

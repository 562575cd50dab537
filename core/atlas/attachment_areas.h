#pragma once
// Attachment areas: where a muscle meets a bone near one end of its action
// line. The area is the patch of bone faces whose centroid lies within
// `contact_distance_mm` of the muscle surface and within `radius_mm` of the
// action line's end point. When the muscle does not reach the bone there
// (its tendon is not part of the surface), the patch falls back to the bone
// faces within `fallback_radius_mm` of the bone point closest to the end.

#include <Eigen/Core>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::atlas {

struct AttachmentOptions {
  double contact_distance_mm = 3.0;
  double radius_mm = 30.0;
  double fallback_radius_mm = 8.0;
};

// `bone_name` is stored in the result; `bone` is the bone's full-resolution
// surface (its tree); `muscle` the muscle surface's tree; `end` the action
// line's end point (mm). `fell_back` (when given) tells whether the fallback
// was used.
AttachmentArea find_attachment_area(const std::string& bone_name, const mesh::AabbTree& bone,
                                    const mesh::AabbTree& muscle, const Eigen::Vector3d& end,
                                    const AttachmentOptions& options = {},
                                    bool* fell_back = nullptr);

// The union of two areas on the same bone (faces merged, area and centroid
// recomputed from `bone`).
AttachmentArea merge_attachment_areas(const AttachmentArea& a, const AttachmentArea& b,
                                      const mesh::IndexedMesh& bone);

}  // namespace mmm::atlas

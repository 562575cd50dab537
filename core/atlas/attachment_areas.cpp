#include "core/atlas/attachment_areas.h"

#include <algorithm>
#include <set>

namespace mmm::atlas {
namespace {

Eigen::Vector3d face_centroid(const mesh::IndexedMesh& surface, int face) {
  return (surface.V.row(surface.F(face, 0)) + surface.V.row(surface.F(face, 1)) +
          surface.V.row(surface.F(face, 2)))
             .transpose() /
         3.0;
}

double face_area(const mesh::IndexedMesh& surface, int face) {
  const Eigen::Vector3d a = surface.V.row(surface.F(face, 0)).transpose();
  const Eigen::Vector3d b = surface.V.row(surface.F(face, 1)).transpose();
  const Eigen::Vector3d c = surface.V.row(surface.F(face, 2)).transpose();
  return 0.5 * (b - a).cross(c - a).norm();
}

void measure(AttachmentArea& area, const mesh::IndexedMesh& surface) {
  area.area_mm2 = 0.0;
  area.centroid.setZero();
  for (const int face : area.faces) {
    const double weight = face_area(surface, face);
    area.area_mm2 += weight;
    area.centroid += weight * face_centroid(surface, face);
  }
  if (area.area_mm2 > 0) area.centroid /= area.area_mm2;
}

}  // namespace

AttachmentArea find_attachment_area(const std::string& bone_name, const mesh::AabbTree& bone,
                                    const mesh::AabbTree& muscle, const Eigen::Vector3d& end,
                                    const AttachmentOptions& options, bool* fell_back) {
  const mesh::IndexedMesh& surface = bone.mesh();
  AttachmentArea area;
  area.bone = bone_name;
  const double contact_sq = options.contact_distance_mm * options.contact_distance_mm;
  const double radius_sq = options.radius_mm * options.radius_mm;
  for (int f = 0; f < static_cast<int>(surface.F.rows()); ++f) {
    const Eigen::Vector3d centre = face_centroid(surface, f);
    if ((centre - end).squaredNorm() > radius_sq) continue;
    if (muscle.closest_point_within(centre, contact_sq)) area.faces.push_back(f);
  }
  const bool fallback = area.faces.empty();
  if (fallback) {
    const Eigen::Vector3d anchor = bone.closest_point(end).point;
    const double fallback_sq = options.fallback_radius_mm * options.fallback_radius_mm;
    for (int f = 0; f < static_cast<int>(surface.F.rows()); ++f) {
      if ((face_centroid(surface, f) - anchor).squaredNorm() <= fallback_sq) {
        area.faces.push_back(f);
      }
    }
    if (area.faces.empty()) area.faces.push_back(bone.closest_point(end).face);
  }
  if (fell_back != nullptr) *fell_back = fallback;
  measure(area, surface);
  return area;
}

AttachmentArea merge_attachment_areas(const AttachmentArea& a, const AttachmentArea& b,
                                      const mesh::IndexedMesh& bone) {
  std::set<int> faces(a.faces.begin(), a.faces.end());
  faces.insert(b.faces.begin(), b.faces.end());
  AttachmentArea merged;
  merged.bone = a.bone;
  merged.faces.assign(faces.begin(), faces.end());
  measure(merged, bone);
  return merged;
}

}  // namespace mmm::atlas

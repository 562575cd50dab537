#include "core/atlas/bone_contacts.h"

#include <Eigen/Geometry>
#include <memory>

#include "core/mesh/mass_properties.h"
#include "core/mesh/penetration.h"
#include "core/mesh/signed_distance.h"
#include "core/mesh/surface_distance.h"

namespace mmm::atlas {

BoneContact contact_between(const NamedSurface& a, const mesh::SignedDistance& a_distance,
                            const NamedSurface& b, const mesh::SignedDistance& b_distance) {
  BoneContact contact;
  contact.a = a.name;
  contact.b = b.name;
  const mesh::PenetrationReport a_in_b = mesh::penetration(*a.surface, b_distance);
  const mesh::PenetrationReport b_in_a = mesh::penetration(*b.surface, a_distance);
  contact.overlap_mm = std::max(a_in_b.max_depth, b_in_a.max_depth);
  if (contact.overlap_mm > 0) {
    contact.entering = a_in_b.max_depth >= b_in_a.max_depth ? a.name : b.name;
    return contact;  // gap 0
  }
  contact.gap_mm = std::min(mesh::distances_to_surface(a.surface->V, b_distance.tree()).minCoeff(),
                            mesh::distances_to_surface(b.surface->V, a_distance.tree()).minCoeff());
  return contact;
}

BoneContact contact_between(const NamedSurface& a, const NamedSurface& b) {
  const mesh::SignedDistance a_distance(*a.surface);
  const mesh::SignedDistance b_distance(*b.surface);
  return contact_between(a, a_distance, b, b_distance);
}

const mesh::SignedDistance& SurfaceDistances::of(const NamedSurface& surface) {
  std::unique_ptr<mesh::SignedDistance>& distance = built_[surface.name];
  if (distance == nullptr) distance = std::make_unique<mesh::SignedDistance>(*surface.surface);
  return *distance;
}

std::vector<BoneContact> bone_contacts(const std::vector<NamedSurface>& bones, double reach_mm) {
  std::vector<Eigen::AlignedBox3d> boxes;
  std::vector<std::unique_ptr<mesh::SignedDistance>> distances;
  for (const NamedSurface& bone : bones) {
    Eigen::AlignedBox3d box = mesh::bounding_box(*bone.surface);
    box.min().array() -= reach_mm;
    box.max().array() += reach_mm;
    boxes.push_back(box);
    distances.push_back(std::make_unique<mesh::SignedDistance>(*bone.surface));
  }
  std::vector<BoneContact> contacts;
  for (std::size_t i = 0; i < bones.size(); ++i) {
    for (std::size_t j = i + 1; j < bones.size(); ++j) {
      if (!boxes[i].intersects(boxes[j])) continue;
      BoneContact contact = contact_between(bones[i], *distances[i], bones[j], *distances[j]);
      if (contact.gap_mm <= reach_mm) contacts.push_back(std::move(contact));
    }
  }
  return contacts;
}

}  // namespace mmm::atlas

#include "core/atlas/anatomy_check.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "core/atlas/millimetres_text.h"
#include "core/mesh/mass_properties.h"

namespace mmm::atlas {
namespace {

bool tagged(const Bone& bone, const std::string& tag) {
  return std::ranges::find(bone.tags, tag) != bone.tags.end();
}

// The bone a bone is welded to, followed to the one a real joint moves.
std::string side_of(const Atlas& atlas, const std::string& bone_name) {
  std::string current = bone_name;
  for (std::size_t guard = 0; guard <= atlas.bones.size(); ++guard) {
    const Bone* bone = atlas.find_bone(current);
    if (bone == nullptr || bone->parent_joint.empty()) return current;
    const Joint* joint = atlas.find_joint(bone->parent_joint);
    if (joint == nullptr || joint->type != JointType::kWeld) return current;
    current = joint->parent;
  }
  return current;
}

const BoneContact* find_contact(const std::vector<BoneContact>& contacts, const std::string& a,
                                const std::string& b) {
  for (const BoneContact& contact : contacts) {
    if ((contact.a == a && contact.b == b) || (contact.a == b && contact.b == a)) return &contact;
  }
  return nullptr;
}

Eigen::AlignedBox3d box_of(const mesh::IndexedMesh& surface, double grown_by) {
  Eigen::AlignedBox3d box = mesh::bounding_box(surface);
  box.min().array() -= grown_by;
  box.max().array() += grown_by;
  return box;
}

// The cartilages (with a surface at hand) on any of `sides` bones.
std::vector<std::string> cartilages_on(const Atlas& atlas,
                                       const std::map<std::string, mesh::IndexedMesh>& structures,
                                       const std::set<std::string>& sides) {
  std::vector<std::string> names;
  for (const Structure& structure : atlas.structures) {
    if (structure.kind != StructureKind::kCartilage || structure.bones.empty()) continue;
    if (sides.contains(structure.bones.front()) && structures.contains(structure.name)) {
      names.push_back(structure.name);
    }
  }
  return names;
}

// The facing cartilage pairs of one articulation, measured and held
// against the limits.
void check_cartilages(const std::string& articulation, const std::vector<std::string>& one,
                      const std::vector<std::string>& other,
                      const std::map<std::string, mesh::IndexedMesh>& structures,
                      SurfaceDistances& distances, const AnatomyLimits& limits,
                      AnatomyReport& report, std::vector<std::string>& problems) {
  if (one.empty() || other.empty()) return;
  bool facing = false;
  for (const std::string& a : one) {
    const mesh::IndexedMesh& a_surface = structures.at(a);
    const Eigen::AlignedBox3d a_box = box_of(a_surface, 0.5 * limits.cartilage_reach_mm);
    for (const std::string& b : other) {
      const mesh::IndexedMesh& b_surface = structures.at(b);
      if (!a_box.intersects(box_of(b_surface, 0.5 * limits.cartilage_reach_mm))) continue;
      facing = true;
      const NamedSurface first{a, &a_surface};
      const NamedSurface second{b, &b_surface};
      const BoneContact contact =
          contact_between(first, distances.of(first), second, distances.of(second));
      report.cartilage_contacts.push_back({articulation, a, b, contact.gap_mm, contact.overlap_mm});
      std::string pair = "articulation ";
      pair += articulation;
      pair += ": cartilages ";
      pair += a;
      pair += " and ";
      pair += b;
      if (contact.gap_mm > limits.max_cartilage_gap_mm) {
        problems.push_back(pair + " are " + millimetres_text(contact.gap_mm) + " apart (at most " +
                           millimetres_text(limits.max_cartilage_gap_mm) + " allowed)");
      }
      if (contact.overlap_mm > limits.max_cartilage_overlap_mm) {
        problems.push_back(pair + " overlap by " + millimetres_text(contact.overlap_mm) +
                           " (at most " + millimetres_text(limits.max_cartilage_overlap_mm) +
                           " allowed)");
      }
    }
  }
  if (!facing) {
    problems.push_back("articulation " + articulation + ": no cartilage of " + one.front() +
                       "'s side faces one of the other side within " +
                       millimetres_text(limits.cartilage_reach_mm) +
                       " (a displaced bone or cartilage?)");
  }
}

}  // namespace

AnatomyReport check_anatomy(const Atlas& atlas,
                            const std::map<std::string, mesh::IndexedMesh>& bones,
                            const std::map<std::string, mesh::IndexedMesh>& structures,
                            const AnatomyLimits& limits, std::vector<std::string>& problems) {
  AnatomyReport report;
  // Each cartilage, ligament and bone they meet measured with one signed
  // distance (the distal femur's cartilage faces both plateaus and the patella).
  SurfaceDistances distances;
  std::vector<NamedSurface> surfaces;
  for (const Bone& bone : atlas.bones) {
    const auto it = bones.find(bone.name);
    if (it != bones.end()) surfaces.push_back({bone.name, &it->second});
  }
  const double reach = std::max(limits.max_neighbour_gap_mm, limits.max_joint_gap_mm) + 5.0;
  report.contacts = bone_contacts(surfaces, reach);

  for (const BoneContact& contact : report.contacts) {
    if (contact.overlap_mm > limits.max_bone_overlap_mm) {
      const std::string& other = contact.entering == contact.a ? contact.b : contact.a;
      problems.push_back("bone " + contact.entering + " enters " + other + " by " +
                         millimetres_text(contact.overlap_mm) + " (at most " +
                         millimetres_text(limits.max_bone_overlap_mm) + " allowed)");
    }
  }
  for (const NamedSurface& bone : surfaces) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const BoneContact& contact : report.contacts) {
      if (contact.a == bone.name || contact.b == bone.name) {
        nearest = std::min(nearest, contact.gap_mm);
      }
    }
    if (!std::isfinite(nearest)) {
      // Beyond the reach of the contacts: measured against every bone.
      for (const NamedSurface& other : surfaces) {
        if (other.name != bone.name)
          nearest = std::min(nearest, contact_between(bone, other).gap_mm);
      }
    }
    report.nearest_neighbour_gap_mm[bone.name] = nearest;
    if (surfaces.size() > 1 && nearest > limits.max_neighbour_gap_mm) {
      problems.push_back("bone " + bone.name + " is " + millimetres_text(nearest) +
                         " from its nearest neighbour (at most " +
                         millimetres_text(limits.max_neighbour_gap_mm) + " allowed)");
    }
  }

  const auto add_articulation = [&](const std::string& name, const std::set<std::string>& one,
                                    const std::set<std::string>& other) {
    Articulation best{name, "", "", std::numeric_limits<double>::infinity(), 0.0};
    for (const std::string& a : one) {
      for (const std::string& b : other) {
        const BoneContact* contact = find_contact(report.contacts, a, b);
        if (contact != nullptr && contact->gap_mm < best.gap_mm) {
          best = {name, a, b, contact->gap_mm, contact->overlap_mm};
        }
      }
    }
    if (best.a.empty()) {
      // Beyond the reach of the contacts: measured pair by pair.
      for (const std::string& a : one) {
        for (const std::string& b : other) {
          const BoneContact contact = contact_between({a, &bones.at(a)}, {b, &bones.at(b)});
          if (best.a.empty() || contact.gap_mm < best.gap_mm) {
            best = {name, a, b, contact.gap_mm, contact.overlap_mm};
          }
        }
      }
    }
    if (best.gap_mm > limits.max_joint_gap_mm) {
      problems.push_back("articulation " + name + ": " + best.a + " and " + best.b + " are " +
                         millimetres_text(best.gap_mm) + " apart (at most " +
                         millimetres_text(limits.max_joint_gap_mm) + " allowed)");
    }
    report.articulations.push_back(best);
    check_cartilages(name, cartilages_on(atlas, structures, one),
                     cartilages_on(atlas, structures, other), structures, distances, limits, report,
                     problems);
  };
  const auto members = [&](const std::string& side) {
    std::set<std::string> names;
    for (const NamedSurface& bone : surfaces) {
      if (side_of(atlas, bone.name) == side && !tagged(*atlas.find_bone(bone.name), "patella")) {
        names.insert(bone.name);
      }
    }
    return names;
  };
  for (const Joint& joint : atlas.joints) {
    if (joint.type == JointType::kWeld) continue;
    const std::set<std::string> parent = members(side_of(atlas, joint.parent));
    const std::set<std::string> child = members(side_of(atlas, joint.child));
    if (parent.empty() || child.empty()) continue;
    add_articulation(joint.name, parent, child);
  }
  for (const Bone& patella : atlas.bones) {
    if (!tagged(patella, "patella") || !bones.contains(patella.name)) continue;
    std::set<std::string> femurs;
    for (const Bone& bone : atlas.bones) {
      if (tagged(bone, "femur") && bones.contains(bone.name)) femurs.insert(bone.name);
    }
    if (femurs.empty()) continue;
    const std::string side = patella.name.ends_with("_l") ? "_l" : "_r";
    add_articulation("patellofemoral" + side, {patella.name}, femurs);
  }

  for (const Structure& structure : atlas.structures) {
    const auto surface = structures.find(structure.name);
    if (surface == structures.end()) continue;
    for (const std::string& bone : structure.bones) {
      if (!bones.contains(bone)) continue;
      const NamedSurface carried{structure.name, &surface->second};
      const NamedSurface carrier{bone, &bones.at(bone)};
      const double gap =
          contact_between(carried, distances.of(carried), carrier, distances.of(carrier)).gap_mm;
      report.structure_attachments.push_back({structure.name, bone, gap});
      if (gap > limits.max_structure_gap_mm) {
        problems.push_back(std::string(structure_kind_name(structure.kind)) + " " + structure.name +
                           " is " + millimetres_text(gap) + " from its bone " + bone +
                           " (at most " + millimetres_text(limits.max_structure_gap_mm) +
                           " allowed)");
      }
    }
  }

  const Landmark* head = atlas.find_landmark("femoral_head_centre_r");
  const Landmark* socket = atlas.find_landmark("acetabulum_centre_r");
  if (head != nullptr && socket != nullptr) {
    report.hip_centre_offset_mm = (head->position - socket->position).norm();
    if (report.hip_centre_offset_mm > limits.max_hip_centre_offset_mm) {
      problems.push_back("the femoral head is " + millimetres_text(report.hip_centre_offset_mm) +
                         " from the centre of the acetabulum (at most " +
                         millimetres_text(limits.max_hip_centre_offset_mm) + " allowed)");
    }
  }
  return report;
}

}  // namespace mmm::atlas

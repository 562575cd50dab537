#pragma once
// How the bones of an atlas meet: for every pair of bones that come within
// `reach_mm` of each other, the gap between their surfaces (0 when they
// overlap) and how deep one enters the other. `mmm atlas check` holds these
// against limits: no bone inside another, no bone away from all its
// neighbours, every joint's bones close (atlas_check.h).

#include <Eigen/Core>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/signed_distance.h"

namespace mmm::atlas {

struct NamedSurface {
  std::string name;
  const mesh::IndexedMesh* surface = nullptr;
};

struct BoneContact {
  std::string a;
  std::string b;
  double gap_mm = 0.0;      // smallest vertex-to-surface distance; 0 when they overlap
  double overlap_mm = 0.0;  // deepest vertex of one inside the other
  std::string entering;     // the bone whose vertex goes deepest (empty when none)
};

// Every pair whose bounding boxes, grown by `reach_mm`, meet and whose gap is
// at most `reach_mm`. Pairs in the order of `bones`.
std::vector<BoneContact> bone_contacts(const std::vector<NamedSurface>& bones, double reach_mm);

// The gap between two surfaces (both directions) and their overlap, whatever
// the distance.
BoneContact contact_between(const NamedSurface& a, const NamedSurface& b);

// The same with the two surfaces' signed distances already built (a surface
// measured against several others builds its own once).
BoneContact contact_between(const NamedSurface& a, const mesh::SignedDistance& a_distance,
                            const NamedSurface& b, const mesh::SignedDistance& b_distance);

// Signed distances of named surfaces, each built the first time it is asked
// for. Not thread-safe.
class SurfaceDistances {
 public:
  const mesh::SignedDistance& of(const NamedSurface& surface);

 private:
  std::map<std::string, std::unique_ptr<mesh::SignedDistance>> built_;
};

}  // namespace mmm::atlas

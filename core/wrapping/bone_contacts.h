#pragma once
// Which vertices of a deforming muscle lie inside a moving bone, and where
// to pin them: the contact query of the volume-preserving deformation, and
// the penetration metric of muscle wrapping.
//
// Each bone is a signed-distance function of its rest surface (closed,
// outward; winding-number sign), posed by its rest -> frame rigid motion.
// A vertex x is tested against a bone only when x mapped back to the bone's
// rest frame, y, lies in the bone's box and the Lipschitz bound cannot clear
// it: sd(y) >= sd(X) - |y - X| with X the vertex at rest and sd(X) measured
// once. Most vertices of most muscles never reach a bone's surface, so a
// frame costs a few exact queries, not #V x #bones.

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "core/mesh/signed_distance.h"
#include "core/wrapping/volume_deformer.h"

namespace mmm::wrapping {

struct PosableBone {
  std::string name;
  std::shared_ptr<const mesh::SignedDistance> surface;  // rest frame (mm)
};

struct ContactOptions {
  double tolerance_mm = 0.1;  // a vertex deeper than this becomes a contact
  double clearance_mm = 0.0;  // contacts are pinned this far outside the surface
};

struct PenetrationMetrics {
  double max_depth_mm = 0.0;  // deepest vertex inside any bone (0: none inside)
  int vertices_inside = 0;    // inside any bone, at any depth
  int vertices_deeper = 0;    // deeper than the tolerance
  std::string deepest_bone;   // where max_depth_mm is reached ("" when none)
};

class BoneContacts {
 public:
  // rest_vertices: the muscle at rest, in the bones' rest frame (mm).
  BoneContacts(Eigen::MatrixX3d rest_vertices, std::vector<PosableBone> bones,
               const ContactOptions& options = {});

  // Vertices of x (frame, mm) deeper than the tolerance in a bone posed by
  // poses[b] (rest -> frame, one per bone in the constructor's order), not
  // flagged in `active`, each with a target `clearance_mm` outside.
  [[nodiscard]] std::vector<Contact> find(const Eigen::MatrixX3d& x,
                                          const std::vector<Eigen::Isometry3d>& poses,
                                          const std::vector<char>& active) const;

  [[nodiscard]] PenetrationMetrics measure(const Eigen::MatrixX3d& x,
                                           const std::vector<Eigen::Isometry3d>& poses) const;

  // Rest signed distance of every vertex to bone b (mm; +infinity outside the box).
  [[nodiscard]] const Eigen::VectorXd& rest_distance(std::size_t b) const {
    return rest_distance_[b];
  }
  [[nodiscard]] const std::vector<PosableBone>& bones() const { return bones_; }
  [[nodiscard]] const ContactOptions& options() const { return options_; }

 private:
  struct Hit {
    int vertex;
    std::size_t bone;
    double depth;
    Eigen::Vector3d target;
  };
  // Every vertex inside some bone (the deepest bone per vertex), with its
  // pin target.
  [[nodiscard]] std::vector<Hit> inside(const Eigen::MatrixX3d& x,
                                        const std::vector<Eigen::Isometry3d>& poses) const;

  Eigen::MatrixX3d rest_;
  std::vector<PosableBone> bones_;
  std::vector<Eigen::AlignedBox3d> boxes_;
  std::vector<Eigen::VectorXd> rest_distance_;
  ContactOptions options_;
};

}  // namespace mmm::wrapping

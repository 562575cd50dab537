#pragma once
// A fine surface carried by its coarse outer hull: the coarse-to-fine step of
// muscle wrapping (the hull is solved first, the fine mesh starts from where
// the hull takes it).
//
// At rest every fine vertex p is tied to its closest point on the hull,
// q = sum_k b_k H_k on face (H_0, H_1, H_2), and keeps its offset o = p - q.
// With the hull deformed to h:
//
//   R_k   the rotation that best carries vertex k's rest one-ring edges onto
//         the deformed ones (polar decomposition of sum_j (h_j - h_k)(H_j - H_k)^T)
//   R     the b-weighted blend of R_0, R_1, R_2, projected back onto rotations
//   p'    sum_k b_k h_k + R o
//
// A rigid motion of the hull carries every fine vertex by exactly that motion.

#include <Eigen/Core>
#include <vector>

#include "core/mesh/mesh.h"

namespace mmm::wrapping {

class HullEmbedding {
 public:
  // rest_hull: closed triangle mesh; rest_fine: #V by 3 (same frame, mm).
  // Throws InvalidInputError on an empty hull, invalid indices or non-finite
  // coordinates.
  HullEmbedding(const mesh::IndexedMesh& rest_hull, const Eigen::MatrixX3d& rest_fine);

  struct Transfer {
    Eigen::MatrixX3d positions;              // #V by 3 (mm)
    std::vector<Eigen::Matrix3d> rotations;  // #V
  };
  // hull: the hull's deformed vertices (same count and order as at rest).
  // Throws InvalidInputError on a count mismatch.
  [[nodiscard]] Transfer transfer(const Eigen::MatrixX3d& hull) const;

  // Largest |o| over the fine vertices (mm): how far inside the hull the
  // fine surface lies at worst.
  [[nodiscard]] double max_offset() const;

 private:
  Eigen::MatrixX3d rest_hull_;
  Eigen::MatrixX3i hull_faces_;
  std::vector<std::vector<int>> neighbours_;  // hull one-rings
  Eigen::VectorXi face_;                      // per fine vertex
  Eigen::MatrixX3d barycentric_;              // per fine vertex
  Eigen::MatrixX3d offset_;                   // per fine vertex, rest
};

}  // namespace mmm::wrapping

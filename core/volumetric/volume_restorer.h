#pragma once
// Every muscle's volume back to its rest volume, for the volumetric
// simulation (tet_simulation.h): Newton steps on all muscles at once. Per
// muscle l, the volume of its closed outward boundary on the output nodes y
// and its gradient dV_l/dy_a = sum over faces (y_b x y_c) / 6, carried to the
// element nodes through the embedding (G_l = W^T dV_l/dy; the nodes that must
// not move left out). Neighbours share nodes, so the step x += sum_l lambda_l
// G_l solves the Gram system sum_m <G_l, G_m> lambda_m = target_l - V_l.

#include <Eigen/Core>
#include <vector>

#include "core/volumetric/coarse_embedding.h"

namespace mmm::volumetric {

// Volume enclosed by each closed outward surface (faces on the nodes y).
std::vector<double> boundary_volumes(const std::vector<Eigen::MatrixX3i>& boundaries,
                                     const Eigen::MatrixX3d& y);

class VolumeRestorer {
 public:
  // `weights` must outlive the restorer. `fixed`: per element node, 1 when
  // the steps must not move it.
  VolumeRestorer(const EmbeddingWeights& weights, std::vector<Eigen::MatrixX3i> boundaries,
                 std::vector<double> targets, std::vector<char> fixed);

  [[nodiscard]] std::vector<double> volumes(const Eigen::MatrixX3d& y) const {
    return boundary_volumes(boundaries_, y);
  }

  // `steps` Newton steps on the element nodes x; y = W x is kept up to date.
  void restore(Eigen::MatrixX3d& x, Eigen::MatrixX3d& y, int steps, int threads) const;

 private:
  const EmbeddingWeights& weights_;
  std::vector<Eigen::MatrixX3i> boundaries_;  // per label, on the output nodes
  std::vector<double> targets_;
  std::vector<char> fixed_;  // per element node
};

}  // namespace mmm::volumetric

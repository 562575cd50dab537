#include "core/volumetric/volume_restorer.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <utility>

#include "core/parallel_for.h"

namespace mmm::volumetric {

using Eigen::Vector3d;

std::vector<double> boundary_volumes(const std::vector<Eigen::MatrixX3i>& boundaries,
                                     const Eigen::MatrixX3d& y) {
  std::vector<double> out(boundaries.size(), 0.0);
  for (std::size_t l = 0; l < boundaries.size(); ++l) {
    const Eigen::MatrixX3i& faces = boundaries[l];
    for (Eigen::Index f = 0; f < faces.rows(); ++f) {
      out[l] += y.row(faces(f, 0)).cross(y.row(faces(f, 1))).dot(y.row(faces(f, 2))) / 6.0;
    }
  }
  return out;
}

VolumeRestorer::VolumeRestorer(const EmbeddingWeights& weights,
                               std::vector<Eigen::MatrixX3i> boundaries,
                               std::vector<double> targets, std::vector<char> fixed)
    : weights_(weights),
      boundaries_(std::move(boundaries)),
      targets_(std::move(targets)),
      fixed_(std::move(fixed)) {}

void VolumeRestorer::restore(Eigen::MatrixX3d& x, Eigen::MatrixX3d& y, int steps,
                             int threads) const {
  const auto muscles = static_cast<Eigen::Index>(boundaries_.size());
  if (muscles == 0) return;
  const Eigen::Index n = x.rows();
  for (int step = 0; step < steps; ++step) {
    // Per muscle, its gradient on the element nodes (sparse: node, vector).
    std::vector<std::vector<std::pair<int, Vector3d>>> gradient(boundaries_.size());
    Eigen::VectorXd residual(muscles);
    parallel_for(boundaries_.size(), threads, [&](std::size_t l) {
      std::vector<int> slot(static_cast<std::size_t>(n), -1);
      std::vector<std::pair<int, Vector3d>>& g = gradient[l];
      double volume = 0.0;
      const Eigen::MatrixX3i& faces = boundaries_[l];
      const auto add = [&](int output_node, const Vector3d& d) {
        for (EmbeddingWeights::InnerIterator it(weights_, output_node); it; ++it) {
          const auto node = static_cast<int>(it.col());
          if (fixed_[static_cast<std::size_t>(node)] != 0) continue;
          int& k = slot[static_cast<std::size_t>(node)];
          if (k < 0) {
            k = static_cast<int>(g.size());
            g.emplace_back(node, Vector3d::Zero());
          }
          g[static_cast<std::size_t>(k)].second += it.value() * d;
        }
      };
      for (Eigen::Index f = 0; f < faces.rows(); ++f) {
        const Vector3d a = y.row(faces(f, 0)).transpose();
        const Vector3d b = y.row(faces(f, 1)).transpose();
        const Vector3d c = y.row(faces(f, 2)).transpose();
        volume += a.cross(b).dot(c) / 6.0;
        add(faces(f, 0), b.cross(c) / 6.0);
        add(faces(f, 1), c.cross(a) / 6.0);
        add(faces(f, 2), a.cross(b) / 6.0);
      }
      residual[static_cast<Eigen::Index>(l)] = targets_[l] - volume;
    });
    // Gram matrix: per element node, the muscles whose gradient reaches it.
    std::vector<std::vector<std::pair<int, Vector3d>>> at_node(static_cast<std::size_t>(n));
    for (std::size_t l = 0; l < gradient.size(); ++l) {
      for (const auto& [node, g] : gradient[l])
        at_node[static_cast<std::size_t>(node)].emplace_back(static_cast<int>(l), g);
    }
    Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(muscles, muscles);
    for (const auto& list : at_node) {
      for (const auto& [l, gl] : list) {
        for (const auto& [m, gm] : list) gram(l, m) += gl.dot(gm);
      }
    }
    // A muscle with no free node keeps a zero row: a tiny diagonal keeps
    // the system solvable and leaves it alone.
    const double floor = 1e-12 * std::max(1.0, gram.diagonal().maxCoeff());
    for (Eigen::Index l = 0; l < muscles; ++l) gram(l, l) += floor;
    const Eigen::VectorXd lambda = gram.ldlt().solve(residual);
    for (std::size_t l = 0; l < gradient.size(); ++l) {
      for (const auto& [node, g] : gradient[l])
        x.row(node) += lambda[static_cast<Eigen::Index>(l)] * g.transpose();
    }
    y = weights_ * x;
  }
}

}  // namespace mmm::volumetric

#include "core/wrapping/muscle_interfaces.h"

#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <string>

#include "core/errors.h"
#include "core/parallel_for.h"

namespace mmm::wrapping {

std::vector<std::vector<InterfaceLink>> muscle_interfaces(const MuscleSurfaces& rest,
                                                          double reach_mm, int threads) {
  if (!(reach_mm > 0.0) || !std::isfinite(reach_mm)) {
    throw InvalidInputError("muscle interfaces: the reach must be > 0 mm, not " +
                            std::to_string(reach_mm));
  }
  std::vector<std::vector<InterfaceLink>> links(rest.size());
  parallel_for(rest.size(), threads, [&](std::size_t m) {
    const Eigen::MatrixX3d& x = rest.surface(m).tree().mesh().V;
    std::vector<InterfaceLink> nearest(static_cast<std::size_t>(x.rows()));
    std::vector<double> distance(static_cast<std::size_t>(x.rows()), reach_mm * reach_mm);
    for (std::size_t n = 0; n < rest.size(); ++n) {
      if (n == m) continue;
      Eigen::AlignedBox3d near_n = rest.box(n);
      near_n.min().array() -= reach_mm;
      near_n.max().array() += reach_mm;
      if (!near_n.intersects(rest.box(m))) continue;
      const mesh::IndexedMesh& other = rest.surface(n).tree().mesh();
      for (Eigen::Index v = 0; v < x.rows(); ++v) {
        const Eigen::Vector3d p = x.row(v).transpose();
        const auto k = static_cast<std::size_t>(v);
        if (!near_n.contains(p)) continue;
        const std::optional<mesh::AabbTree::ClosestPoint> closest =
            rest.surface(n).tree().closest_point_within(p, distance[k]);
        if (!closest || closest->squared_distance >= distance[k]) continue;
        Eigen::Index corner = 0;
        closest->barycentric.maxCoeff(&corner);
        const int u = other.F(closest->face, static_cast<int>(corner));
        distance[k] = closest->squared_distance;
        nearest[k] = {static_cast<int>(v), static_cast<int>(n), u, 0.0,
                      p - other.V.row(u).transpose()};
      }
    }
    for (std::size_t k = 0; k < nearest.size(); ++k) {
      if (nearest[k].muscle < 0) continue;
      const double t = 1.0 - std::sqrt(distance[k]) / reach_mm;
      nearest[k].weight = 0.5 * t * t;
      if (nearest[k].weight > 0.0) links[m].push_back(nearest[k]);
    }
  });
  return links;
}

MuscleBinding::Targets blend_interfaces(const MuscleBinding::Targets& own,
                                        const std::vector<InterfaceLink>& links,
                                        const std::vector<const MuscleBinding::Targets*>& all,
                                        const Eigen::VectorXd& bone_blend) {
  MuscleBinding::Targets blended = own;
  for (const InterfaceLink& link : links) {
    const double beta = link.weight * (1.0 - bone_blend[link.vertex]);
    if (beta <= 0.0) continue;
    const MuscleBinding::Targets& other = *all[static_cast<std::size_t>(link.muscle)];
    const auto u = static_cast<std::size_t>(link.other_vertex);
    const Eigen::Matrix3d& turn = other.rotations[u];
    const Eigen::Vector3d carried =
        other.positions.row(link.other_vertex).transpose() + turn * link.offset;
    const auto v = static_cast<std::size_t>(link.vertex);
    blended.positions.row(link.vertex) =
        (1.0 - beta) * own.positions.row(link.vertex) + beta * carried.transpose();
    const Eigen::Quaterniond mine(own.rotations[v]);
    blended.rotations[v] = mine.slerp(beta, Eigen::Quaterniond(turn)).toRotationMatrix();
  }
  return blended;
}

}  // namespace mmm::wrapping

#include "core/atlas/muscle_cleanup.h"

#include <algorithm>
#include <set>

#include "core/mesh/mass_properties.h"

namespace mmm::atlas {
namespace {

std::vector<std::vector<int>> vertex_neighbours(const mesh::IndexedMesh& surface) {
  std::vector<std::set<int>> sets(static_cast<std::size_t>(surface.V.rows()));
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = surface.F(f, k);
      const int b = surface.F(f, (k + 1) % 3);
      sets[static_cast<std::size_t>(a)].insert(b);
      sets[static_cast<std::size_t>(b)].insert(a);
    }
  }
  std::vector<std::vector<int>> neighbours(sets.size());
  for (std::size_t i = 0; i < sets.size(); ++i)
    neighbours[i].assign(sets[i].begin(), sets[i].end());
  return neighbours;
}

// Deepest penetration of vertex `v` into any bone: depth (> 0 inside) and
// the bone's closest surface point.
struct Penetration {
  double depth = 0.0;
  Eigen::Vector3d surface_point = Eigen::Vector3d::Zero();
};

Penetration deepest(const Eigen::Vector3d& point,
                    const std::vector<const mesh::SignedDistance*>& bones) {
  Penetration result;
  for (const mesh::SignedDistance* bone : bones) {
    if (!bone->tree().bounds().contains(point)) continue;
    const double distance = bone->at(point);
    if (-distance > result.depth) {
      result.depth = -distance;
      result.surface_point = bone->tree().closest_point(point).point;
    }
  }
  return result;
}

}  // namespace

MuscleCleanupReport push_muscle_out_of_bones(mesh::IndexedMesh& muscle,
                                             const std::vector<const mesh::SignedDistance*>& bones,
                                             const MuscleCleanupOptions& options) {
  MuscleCleanupReport report;
  report.volume_before_mm3 = mesh::signed_volume(muscle);
  const auto neighbours = vertex_neighbours(muscle);
  std::vector<bool> ever_moved(static_cast<std::size_t>(muscle.V.rows()), false);
  // Round 0 looks at every vertex; later rounds only at those the previous
  // round moved or relaxed (nothing else changed).
  std::vector<int> candidates(static_cast<std::size_t>(muscle.V.rows()));
  for (std::size_t v = 0; v < candidates.size(); ++v) candidates[v] = static_cast<int>(v);
  for (int round = 0; round < options.max_rounds && !candidates.empty(); ++round) {
    std::vector<int> moved;
    double round_depth = 0.0;
    for (const int v : candidates) {
      const Eigen::Vector3d point = muscle.V.row(v).transpose();
      const Penetration hit = deepest(point, bones);
      round_depth = std::max(round_depth, hit.depth);
      if (hit.depth <= options.tolerance_mm) continue;
      const Eigen::Vector3d outward = (hit.surface_point - point).normalized();
      muscle.V.row(v) = (hit.surface_point + options.margin_mm * outward).transpose();
      moved.push_back(v);
      ever_moved[static_cast<std::size_t>(v)] = true;
    }
    if (round == 0) report.max_depth_before_mm = round_depth;
    if (moved.empty()) break;
    // Relax the 2-ring around the moved vertices, the moved ones held.
    std::set<int> held(moved.begin(), moved.end());
    std::set<int> ring;
    for (const int v : moved) {
      for (const int n : neighbours[static_cast<std::size_t>(v)]) {
        ring.insert(n);
        for (const int m : neighbours[static_cast<std::size_t>(n)]) ring.insert(m);
      }
    }
    for (const int v : held) ring.erase(v);
    for (int iteration = 0; iteration < options.smoothing_iterations; ++iteration) {
      for (const int v : ring) {
        const auto& around = neighbours[static_cast<std::size_t>(v)];
        if (around.empty()) continue;
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (const int n : around) mean += muscle.V.row(n).transpose();
        mean /= static_cast<double>(around.size());
        muscle.V.row(v) = (0.5 * muscle.V.row(v).transpose() + 0.5 * mean).transpose();
      }
    }
    candidates.assign(ring.begin(), ring.end());
    candidates.insert(candidates.end(), moved.begin(), moved.end());
  }
  for (Eigen::Index v = 0; v < muscle.V.rows(); ++v) {
    report.max_depth_after_mm =
        std::max(report.max_depth_after_mm, deepest(muscle.V.row(v).transpose(), bones).depth);
  }
  report.vertices_moved = static_cast<int>(std::ranges::count(ever_moved, true));
  report.volume_after_mm3 = mesh::signed_volume(muscle);
  return report;
}

}  // namespace mmm::atlas

#include "core/wrapping/muscle_penetration.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/parallel_for.h"
#include "core/wrapping/muscle_wrapping.h"

namespace mmm::wrapping {
namespace {

Eigen::AlignedBox3d bounds(const Eigen::MatrixX3d& x) {
  Eigen::AlignedBox3d box;
  for (Eigen::Index v = 0; v < x.rows(); ++v) box.extend(Eigen::Vector3d(x.row(v).transpose()));
  return box;
}

// Calls visit(n, v, depth) for every vertex v of x inside another muscle n.
template <typename Visit>
void for_each_inside(int self, const Eigen::MatrixX3d& x, const MuscleSurfaces& others,
                     const Visit& visit) {
  const Eigen::AlignedBox3d own = bounds(x);
  for (std::size_t n = 0; n < others.size(); ++n) {
    if (static_cast<int>(n) == self || !own.intersects(others.box(n))) continue;
    const mesh::SignedDistance& surface = others.surface(n);
    for (Eigen::Index v = 0; v < x.rows(); ++v) {
      const Eigen::Vector3d p = x.row(v).transpose();
      if (!others.box(n).contains(p) || !surface.winding().is_inside(p)) continue;
      visit(static_cast<int>(n), v, std::sqrt(surface.tree().closest_point(p).squared_distance));
    }
  }
}

double rest_depth(const RestOverlap& rest, int n, Eigen::Index v) {
  const auto found = rest.find(n);
  return found == rest.end() ? 0.0 : found->second[v];
}

}  // namespace

MuscleSurfaces::MuscleSurfaces(const std::vector<Eigen::MatrixX3d>& positions,
                               const std::vector<const Eigen::MatrixX3i*>& faces, int threads)
    : surfaces_(positions.size()), boxes_(positions.size()) {
  if (faces.size() != positions.size()) {
    throw InvalidInputError("muscle surfaces: " + std::to_string(positions.size()) +
                            " vertex sets but " + std::to_string(faces.size()) + " face sets");
  }
  parallel_for(positions.size(), threads, [&](std::size_t m) {
    surfaces_[m] =
        std::make_unique<mesh::SignedDistance>(mesh::IndexedMesh{positions[m], *faces[m]});
    boxes_[m] = surfaces_[m]->tree().bounds();
  });
}

RestOverlap rest_overlap(int self, const Eigen::MatrixX3d& x, const MuscleSurfaces& others) {
  RestOverlap overlap;
  for_each_inside(self, x, others, [&](int n, Eigen::Index v, double depth) {
    auto [entry, added] = overlap.try_emplace(n);
    if (added) entry->second = Eigen::VectorXd::Zero(x.rows());
    entry->second[v] = depth;
  });
  return overlap;
}

MusclePenetration measure_muscle_penetration(int self, const Eigen::MatrixX3d& x,
                                             const MuscleSurfaces& others, const RestOverlap& rest,
                                             double tolerance_mm) {
  MusclePenetration result;
  std::vector<char> deeper(static_cast<std::size_t>(x.rows()), 0);
  for_each_inside(self, x, others, [&](int n, Eigen::Index v, double depth) {
    const double excess = depth - rest_depth(rest, n, v);
    if (excess > result.max_depth_mm) {
      result.max_depth_mm = excess;
      result.deepest_muscle = n;
    }
    if (excess > tolerance_mm) deeper[static_cast<std::size_t>(v)] = 1;
  });
  result.vertices_deeper = static_cast<int>(std::count(deeper.begin(), deeper.end(), 1));
  return result;
}

void measure_muscle_penetration(MuscleWrapping& wrapped, double tolerance_mm, int threads) {
  const std::size_t muscles = wrapped.muscles.size();
  std::vector<const Eigen::MatrixX3i*> faces;
  std::vector<Eigen::MatrixX3d> rest;
  for (const WrappedMuscle& muscle : wrapped.muscles) {
    faces.push_back(&muscle.rest.F);
    rest.push_back(muscle.rest.V);
  }
  const MuscleSurfaces rest_surfaces(rest, faces, threads);
  std::vector<RestOverlap> overlaps(muscles);
  parallel_for(muscles, threads, [&](std::size_t m) {
    overlaps[m] = rest_overlap(static_cast<int>(m), rest[m], rest_surfaces);
  });
  const auto frames = static_cast<std::size_t>(wrapped.times.size());
  parallel_for(frames, threads, [&](std::size_t f) {
    std::vector<Eigen::MatrixX3d> positions;
    positions.reserve(muscles);
    for (const WrappedMuscle& muscle : wrapped.muscles)
      positions.emplace_back(muscle.positions[f].cast<double>());
    const MuscleSurfaces now(positions, faces, 1);
    for (std::size_t m = 0; m < muscles; ++m) {
      const MusclePenetration p = measure_muscle_penetration(static_cast<int>(m), positions[m], now,
                                                             overlaps[m], tolerance_mm);
      MuscleFrameMetrics& metrics = wrapped.muscles[m].frames[f];
      metrics.muscle_depth_mm = p.max_depth_mm;
      metrics.muscle_vertices_deeper = p.vertices_deeper;
      metrics.deepest_muscle = p.deepest_muscle;
    }
  });
}

}  // namespace mmm::wrapping

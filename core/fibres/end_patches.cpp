#include "core/fibres/end_patches.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Index;

constexpr int kMinimumVertices = 3;

// Distance from every vertex to the nearest of `points`.
Eigen::VectorXd distances(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3d& points) {
  Eigen::VectorXd nearest(vertices.rows());
  for (Index v = 0; v < vertices.rows(); ++v) {
    nearest(v) = std::sqrt((points.rowwise() - vertices.row(v)).rowwise().squaredNorm().minCoeff());
  }
  return nearest;
}

// The vertices with excess <= margin that `excluded` does not hold; when
// fewer than kMinimumVertices, the kMinimumVertices of least excess that it
// does not hold.
std::vector<int> patch(const Eigen::VectorXd& excess, double margin,
                       const std::vector<bool>& excluded) {
  std::vector<int> chosen;
  std::vector<int> free;
  for (Index v = 0; v < excess.size(); ++v) {
    if (excluded[static_cast<std::size_t>(v)]) continue;
    free.push_back(static_cast<int>(v));
    if (excess(v) <= margin) chosen.push_back(static_cast<int>(v));
  }
  if (static_cast<int>(chosen.size()) < kMinimumVertices) {
    const auto count = std::min<std::size_t>(kMinimumVertices, free.size());
    std::partial_sort(free.begin(), free.begin() + static_cast<std::ptrdiff_t>(count), free.end(),
                      [&](int a, int b) { return excess(a) < excess(b); });
    chosen.assign(free.begin(), free.begin() + static_cast<std::ptrdiff_t>(count));
    std::sort(chosen.begin(), chosen.end());
  }
  return chosen;
}

void check_attachment_area(const Eigen::MatrixX3d& points, const char* which) {
  if (points.rows() == 0 || !points.allFinite()) {
    throw InvalidInputError(std::string("end patches: the ") + which +
                            " area has no points or a point that is not finite; the muscle "
                            "needs both attachment areas in the atlas");
  }
}

}  // namespace

EndPatches end_patches(const mesh::IndexedMesh& surface, const Attachments& areas,
                       double margin_mm) {
  check_attachment_area(areas.origin, "origin");
  check_attachment_area(areas.insertion, "insertion");
  if (!(margin_mm >= 0.0) || !std::isfinite(margin_mm)) {
    throw InvalidInputError("end patches: margin " + std::to_string(margin_mm) +
                            " mm; use a finite margin >= 0 (3 mm)");
  }
  if (surface.V.rows() < Index{2} * kMinimumVertices || !surface.V.allFinite()) {
    throw InvalidInputError(
        "end patches: the surface has fewer than 6 vertices or a non-finite one");
  }
  const Eigen::VectorXd to_origin = distances(surface.V, areas.origin);
  const Eigen::VectorXd to_insertion = distances(surface.V, areas.insertion);
  EndPatches result;
  result.origin_gap_mm = to_origin.minCoeff();
  result.insertion_gap_mm = to_insertion.minCoeff();
  const Eigen::VectorXd origin_excess = to_origin.array() - result.origin_gap_mm;
  const Eigen::VectorXd insertion_excess = to_insertion.array() - result.insertion_gap_mm;
  const auto n = static_cast<std::size_t>(surface.V.rows());
  // A vertex is the origin's only if it exceeds the origin's gap by less.
  std::vector<bool> insertion_side(n);
  for (std::size_t v = 0; v < n; ++v) {
    const auto i = static_cast<Index>(v);
    insertion_side[v] = insertion_excess(i) < origin_excess(i);
  }
  result.origin = patch(origin_excess, margin_mm, insertion_side);
  std::vector<bool> taken(n, false);
  for (const int v : result.origin) taken[static_cast<std::size_t>(v)] = true;
  std::vector<bool> origin_side = taken;
  for (std::size_t v = 0; v < n; ++v) origin_side[v] = origin_side[v] || !insertion_side[v];
  result.insertion = patch(insertion_excess, margin_mm, origin_side);
  if (static_cast<int>(result.insertion.size()) < kMinimumVertices) {
    // Nothing is on the insertion's side: its least-excess vertices not in the origin patch.
    result.insertion = patch(insertion_excess, margin_mm, taken);
  }
  return result;
}

Attachments patch_attachments(const EndPatches& patches, const Eigen::MatrixX3d& positions,
                              const Attachments& areas) {
  const auto rows = [&positions](const std::vector<int>& vertices) {
    Eigen::MatrixX3d points(static_cast<Index>(vertices.size()), 3);
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      points.row(static_cast<Index>(i)) = positions.row(vertices[i]);
    }
    return points;
  };
  return Attachments{rows(patches.origin), rows(patches.insertion), areas.origin_area_mm2,
                     areas.insertion_area_mm2};
}

double patch_gap(const std::vector<int>& patch, const Eigen::MatrixX3d& positions,
                 const Eigen::MatrixX3d& points) {
  double gap = std::numeric_limits<double>::infinity();
  for (const int v : patch) {
    gap = std::min(
        gap, std::sqrt((points.rowwise() - positions.row(v)).rowwise().squaredNorm().minCoeff()));
  }
  return gap;
}

}  // namespace mmm::fibres

#include "core/atlas/surface_line.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/mesh/winding_number.h"

namespace mmm::atlas {
namespace {

// Via points on different bones closer than this pass through each other as
// the joint between them moves (mm).
constexpr double kCrossingGap_mm = 15.0;
constexpr Eigen::Index kFewestContactVertices = 8;

Eigen::Vector3d contact_middle(const mesh::IndexedMesh& muscle, const mesh::AabbTree& bone,
                               double contact_mm) {
  std::vector<std::pair<double, Eigen::Index>> by_distance;
  by_distance.reserve(static_cast<std::size_t>(muscle.V.rows()));
  for (Eigen::Index i = 0; i < muscle.V.rows(); ++i) {
    const Eigen::Vector3d p = muscle.V.row(i).transpose();
    by_distance.emplace_back(bone.closest_point(p).squared_distance, i);
  }
  std::ranges::sort(by_distance);
  Eigen::Index within = 0;
  while (within < static_cast<Eigen::Index>(by_distance.size()) &&
         by_distance[static_cast<std::size_t>(within)].first <= contact_mm * contact_mm) {
    ++within;
  }
  const Eigen::Index nearest = std::max(kFewestContactVertices, muscle.V.rows() / 50);
  const Eigen::Index used =
      std::min<Eigen::Index>(muscle.V.rows(), within >= kFewestContactVertices ? within : nearest);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (Eigen::Index k = 0; k < used; ++k) {
    sum += muscle.V.row(by_distance[static_cast<std::size_t>(k)].second).transpose();
  }
  return bone.closest_point(sum / static_cast<double>(used)).point;
}

// A point inside the muscle for a slice whose centroid is `centre`: the
// centroid itself when it is inside; otherwise (the slice of a sheet curved
// around a bone) the middle of the sheet where a ray from the centroid through
// the nearest surface point crosses it.
Eigen::Vector3d inside_point(const Eigen::Vector3d& centre, const mesh::AabbTree& tree,
                             const mesh::WindingNumber& winding) {
  if (winding.is_inside(centre)) return centre;
  Eigen::Vector3d nearest = tree.closest_point(centre).point;
  const Eigen::Vector3d towards = nearest - centre;
  if (towards.norm() < 1e-9) return centre;
  const std::vector<mesh::AabbTree::RayHit> hits = tree.all_hits(centre, towards.normalized());
  if (hits.size() < 2) return nearest;
  return centre + 0.5 * (hits[0].t + hits[1].t) * towards.normalized();
}

}  // namespace

SurfaceLine surface_action_line(const std::string& name, const mesh::IndexedMesh& muscle,
                                const SurfaceLineBone& origin, const SurfaceLineBone& insertion,
                                double contact_mm) {
  if (muscle.V.rows() == 0 || origin.surface == nullptr || insertion.surface == nullptr) {
    throw InvalidInputError("surface line " + name + ": needs the muscle and both bone surfaces");
  }
  const Eigen::Vector3d start = contact_middle(muscle, *origin.surface, contact_mm);
  const Eigen::Vector3d end = contact_middle(muscle, *insertion.surface, contact_mm);
  const double length = (end - start).norm();
  if (length < 1.0) {
    throw InvalidInputError("surface line " + name + ": its ends on " + origin.name + " and " +
                            insertion.name + " fall together; give two bones the muscle spans");
  }
  const Eigen::Vector3d axis = (end - start) / length;
  const mesh::AabbTree muscle_tree(muscle);
  const mesh::WindingNumber winding(muscle_tree);
  const Eigen::VectorXd along = (muscle.V.rowwise() - start.transpose()) * axis;
  const double low = std::clamp(along.minCoeff(), 0.0, length);
  const double high = std::clamp(along.maxCoeff(), 0.0, length);
  SurfaceLine result;
  result.belly_mm = high - low;  // until measured along the path below
  result.tendon_mm = length - result.belly_mm;
  result.line.name = name;
  const auto point = [&](const std::string& suffix, const std::string& bone,
                         const Eigen::Vector3d& position) {
    PathPoint p;
    p.name = name + "-" + suffix;
    p.bone = bone;
    p.position = position;
    result.line.points.push_back(std::move(p));
  };
  point("P1", origin.name, start);
  // A slice every ~10 mm of belly, 3 to 12 of them.
  const int slices = std::clamp(static_cast<int>(result.belly_mm / 10.0), 3, 12);
  const double width = result.belly_mm / (slices + 1);
  for (int slice = 1; slice <= slices; ++slice) {
    const double centre = low + slice * width;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (Eigen::Index i = 0; i < muscle.V.rows(); ++i) {
      if (std::abs(along(i) - centre) <= 0.5 * width) {
        sum += muscle.V.row(i).transpose();
        ++count;
      }
    }
    if (count == 0) continue;
    const bool nearer_origin = centre < 0.5 * length;
    point("V" + std::to_string(slice), nearer_origin ? origin.name : insertion.name,
          inside_point(sum / count, muscle_tree, winding));
  }
  point("P" + std::to_string(result.line.points.size() + 1), insertion.name, end);
  // The two via points either side of the change of bone sit on different
  // bones: closer than kCrossingGap_mm they pass through each other as the
  // joint moves (a kink in the length, a jump in the moment arm), so they
  // only bend the drawn path (kFollowsLine) and the line of action runs
  // between the points around them.
  std::vector<PathPoint>& line_points = result.line.points;
  for (std::size_t i = 1; i + 2 < line_points.size(); ++i) {
    PathPoint& before = line_points[i];
    PathPoint& after = line_points[i + 1];
    if (before.bone != after.bone && (after.position - before.position).norm() < kCrossingGap_mm) {
      before.kind = PathPointKind::kFollowsLine;
      after.kind = PathPointKind::kFollowsLine;
    }
  }
  // The tendon is what the path runs outside the muscle before it first
  // enters it and after it last leaves it (sampled every 0.5 mm); the belly
  // the rest.
  double travelled = 0.0;
  double first_inside = -1.0;
  double last_inside = -1.0;
  const std::vector<PathPoint>& points = result.line.points;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Eigen::Vector3d from = points[i - 1].position;
    const Eigen::Vector3d step = points[i].position - from;
    const double segment = step.norm();
    const int samples = std::max(1, static_cast<int>(std::ceil(segment / 0.5)));
    for (int k = 0; k < samples; ++k) {
      const double along_segment = segment * k / samples;
      if (winding.is_inside(from + step * (along_segment / std::max(segment, 1e-12)))) {
        if (first_inside < 0) first_inside = travelled + along_segment;
        last_inside = travelled + along_segment;
      }
    }
    travelled += segment;
  }
  if (first_inside >= 0) {
    result.belly_mm = last_inside - first_inside;
    result.tendon_mm = travelled - result.belly_mm;
  }
  return result;
}

}  // namespace mmm::atlas

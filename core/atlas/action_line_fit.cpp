#include "core/atlas/action_line_fit.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>

#include "core/atlas/atlas_check.h"
#include "core/errors.h"

namespace mmm::atlas {
namespace {

struct Geometry {
  const mesh::AabbTree& muscle;
  const std::function<bool(const Eigen::Vector3d&)>& inside;
};

std::vector<Eigen::Vector3d> positions(const ActionLine& line) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(line.points.size());
  for (const PathPoint& point : line.points) points.push_back(point.position);
  return points;
}

double distance_to_polyline(const Eigen::Vector3d& q, const std::vector<Eigen::Vector3d>& line) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const Eigen::Vector3d d = line[i + 1] - line[i];
    const double length_sq = d.squaredNorm();
    const double t = length_sq > 0 ? std::clamp((q - line[i]).dot(d) / length_sq, 0.0, 1.0) : 0.0;
    best = std::min(best, (line[i] + t * d - q).norm());
  }
  if (line.size() == 1) best = (line.front() - q).norm();
  return best;
}

// The centre of the bundle's cross-section in the slab across `direction`
// at `at`: the point of the section deepest inside the muscle among its
// centroid and the midpoints of pairs of its vertices (a C-shaped section,
// as of the vastus intermedius around the femur, has its centroid outside).
std::optional<Eigen::Vector3d> section_centre(const std::vector<Eigen::Vector3d>& bundle,
                                              const Eigen::Vector3d& at,
                                              const Eigen::Vector3d& direction,
                                              const Geometry& geometry,
                                              const ActionLineFitOptions& options) {
  std::vector<Eigen::Vector3d> section;
  const double radius_sq = options.section_radius_mm * options.section_radius_mm;
  for (const Eigen::Vector3d& v : bundle) {
    if (std::abs((v - at).dot(direction)) > options.slab_mm) continue;
    if ((v - at).squaredNorm() > radius_sq) continue;
    section.push_back(v);
  }
  if (section.size() < 6) return std::nullopt;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : section) centroid += v;
  centroid /= static_cast<double>(section.size());
  std::vector<Eigen::Vector3d> candidates{centroid};
  const std::size_t n = section.size();
  const std::size_t stride = std::max<std::size_t>(1, n / 24);
  for (std::size_t i = 0; i < n; i += stride) {
    for (std::size_t j = i + stride; j < n; j += stride) {
      candidates.emplace_back(0.5 * (section[i] + section[j]));
    }
  }
  double best_depth = -1.0;
  Eigen::Vector3d best = centroid;
  for (const Eigen::Vector3d& candidate : candidates) {
    if (!geometry.inside(candidate)) continue;
    const double depth = std::sqrt(geometry.muscle.closest_point(candidate).squared_distance);
    if (depth > best_depth) {
      best_depth = depth;
      best = candidate;
    }
  }
  return best;
}

// Where the bundle touches `bone` near `end`: the bone point nearest the
// centroid of the bundle vertices within contact distance of the bone, or,
// when none is that close, nearest the bundle vertex closest to the bone.
std::optional<Eigen::Vector3d> contact_point(const std::vector<Eigen::Vector3d>& bundle,
                                             const mesh::AabbTree& bone, const Eigen::Vector3d& end,
                                             const ActionLineFitOptions& options) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  double nearest = std::numeric_limits<double>::infinity();
  Eigen::Vector3d nearest_vertex = end;
  const double search_sq = options.search_radius_mm * options.search_radius_mm;
  for (const Eigen::Vector3d& v : bundle) {
    if ((v - end).squaredNorm() > search_sq) continue;
    const auto closest = bone.closest_point(v);
    if (options.articular && options.articular(closest.point)) continue;
    const double distance = closest.squared_distance;
    if (distance < nearest) {
      nearest = distance;
      nearest_vertex = v;
    }
    if (distance > options.contact_mm * options.contact_mm) continue;
    sum += v;
    ++count;
  }
  std::optional<Eigen::Vector3d> contact;
  if (count >= 3) {
    contact = bone.closest_point(sum / count).point;
  } else if (std::isfinite(nearest)) {
    contact = bone.closest_point(nearest_vertex).point;
  }
  if (contact && (*contact - end).norm() > options.max_end_shift_mm) return std::nullopt;
  return contact;
}

Eigen::Vector3d direction_at(const std::vector<Eigen::Vector3d>& line, std::size_t i) {
  const Eigen::Vector3d& before = line[i > 0 ? i - 1 : 0];
  const Eigen::Vector3d& after = line[std::min(i + 1, line.size() - 1)];
  const Eigen::Vector3d d = after - before;
  return d.norm() > 0 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitZ();
}

// The bones from `a` to `b` along the chain (both included; through their
// nearest common ancestor). Without a chain, or when they are not
// connected, just the two.
std::vector<std::string> chain_between(const std::string& a, const std::string& b,
                                       const std::map<std::string, std::string>& parent) {
  const auto ancestors = [&](const std::string& bone) {
    std::vector<std::string> line{bone};
    for (auto it = parent.find(bone); it != parent.end() && line.size() < 64;
         it = parent.find(it->second)) {
      line.push_back(it->second);
    }
    return line;
  };
  const std::vector<std::string> up_a = ancestors(a);
  const std::vector<std::string> up_b = ancestors(b);
  for (std::size_t i = 0; i < up_a.size(); ++i) {
    const auto common = std::find(up_b.begin(), up_b.end(), up_a[i]);
    if (common == up_b.end()) continue;
    std::vector<std::string> chain(up_a.begin(), up_a.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    // Then down from the common ancestor to b.
    chain.insert(chain.end(), std::make_reverse_iterator(common), up_b.rend());
    return chain;
  }
  return {a, b};
}

// The bone a split point at `x` of segment a -> b rides on (see the header).
std::string bone_along_chain(const PathPoint& a, const PathPoint& b, const Eigen::Vector3d& x,
                             const ActionLineFitOptions& options,
                             const std::function<double(const std::string&)>& squared_distance) {
  const std::vector<std::string> chain = chain_between(a.bone, b.bone, options.parent_bone);
  const Eigen::Vector3d along = b.position - a.position;
  // Walking from a to b, each step crosses the joint of the deeper bone.
  std::string chosen = chain.front();
  bool by_joints = true;
  for (std::size_t i = 0; i + 1 < chain.size() && by_joints; ++i) {
    const auto parent = options.parent_bone.find(chain[i]);
    const std::string& child = parent != options.parent_bone.end() && parent->second == chain[i + 1]
                                   ? chain[i]
                                   : chain[i + 1];
    const auto centre = options.joint_centre.find(child);
    if (centre == options.joint_centre.end()) {
      by_joints = false;
      break;
    }
    if ((x - centre->second).dot(along) > 0) chosen = chain[i + 1];
  }
  if (by_joints) return chosen;
  double nearest = std::numeric_limits<double>::infinity();
  for (const std::string& bone : chain) {
    // The segment's own bones must have trees (squared_distance names a
    // missing one); bones in between without one are passed over.
    double distance = std::numeric_limits<double>::infinity();
    try {
      distance = squared_distance(bone);
    } catch (const InvalidInputError&) {
      if (bone == a.bone || bone == b.bone) throw;
    }
    if (distance < nearest) {
      nearest = distance;
      chosen = bone;
    }
  }
  return chosen;
}

}  // namespace

std::vector<ActionLineFitReport> fit_action_lines(
    Muscle& muscle, const mesh::AabbTree& muscle_tree,
    const std::function<bool(const Eigen::Vector3d&)>& inside,
    const std::map<std::string, const mesh::AabbTree*>& bones,
    const ActionLineFitOptions& options) {
  const auto bone_tree = [&](const std::string& name) -> const mesh::AabbTree& {
    const auto it = bones.find(name);
    if (it == bones.end()) {
      throw InvalidInputError("fit_action_lines: muscle " + muscle.name + ": no bone '" + name +
                              "'");
    }
    return *it->second;
  };
  const Geometry geometry{muscle_tree, inside};
  const mesh::IndexedMesh& surface = muscle_tree.mesh();
  // 1. bundles
  std::vector<std::vector<Eigen::Vector3d>> bundles(muscle.action_lines.size());
  std::vector<std::vector<Eigen::Vector3d>> lines;
  for (const ActionLine& line : muscle.action_lines) lines.push_back(positions(line));
  for (Eigen::Index v = 0; v < surface.V.rows(); ++v) {
    const Eigen::Vector3d q = surface.V.row(v).transpose();
    std::size_t best = 0;
    double best_distance = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < lines.size(); ++k) {
      const double d = distance_to_polyline(q, lines[k]);
      if (d < best_distance) {
        best_distance = d;
        best = k;
      }
    }
    if (!lines.empty()) bundles[best].push_back(q);
  }

  std::vector<ActionLineFitReport> reports;
  for (std::size_t k = 0; k < muscle.action_lines.size(); ++k) {
    ActionLine& line = muscle.action_lines[k];
    const std::vector<Eigen::Vector3d>& bundle = bundles[k];
    ActionLineFitReport report;
    report.line = line.name;
    report.inside_before = inside_fraction(positions(line), options.sample_step_mm, inside);
    if (line.points.size() < 2 || bundle.empty()) {
      report.inside_after = report.inside_before;
      reports.push_back(report);
      continue;
    }
    // 2. ends onto the contact
    PathPoint& origin = line.points.front();
    PathPoint& insertion = line.points.back();
    if (origin.kind != PathPointKind::kMoving) {
      if (const auto contact =
              contact_point(bundle, bone_tree(origin.bone), origin.position, options)) {
        origin.position = *contact;
        report.origin_on_contact = true;
      }
    }
    if (insertion.kind != PathPointKind::kMoving) {
      if (const auto contact =
              contact_point(bundle, bone_tree(insertion.bone), insertion.position, options)) {
        insertion.position = *contact;
        report.insertion_on_contact = true;
      }
    }
    // 3. via points onto their section centres
    std::vector<Eigen::Vector3d> current = positions(line);
    for (std::size_t i = 1; i + 1 < line.points.size(); ++i) {
      if (line.points[i].kind == PathPointKind::kMoving) continue;
      if (const auto centre =
              section_centre(bundle, current[i], direction_at(current, i), geometry, options)) {
        if ((*centre - current[i]).norm() > options.max_via_shift_mm) continue;
        line.points[i].position = *centre;
        current[i] = *centre;
      }
    }
    // 4. split segments that leave the muscle
    for (int level = 0; level < options.max_splits; ++level) {
      std::vector<PathPoint> refined{line.points.front()};
      bool split = false;
      for (std::size_t i = 0; i + 1 < line.points.size(); ++i) {
        const PathPoint& a = line.points[i];
        const PathPoint& b = line.points[i + 1];
        const double length = (b.position - a.position).norm();
        if (length >= options.min_segment_mm &&
            inside_fraction({a.position, b.position}, options.sample_step_mm, inside) <
                options.good_fraction) {
          const Eigen::Vector3d middle = 0.5 * (a.position + b.position);
          if (const auto centre = section_centre(
                  bundle, middle, (b.position - a.position).normalized(), geometry, options)) {
            PathPoint added;
            added.name = line.name + "-fit" + std::to_string(report.points_added + 1);
            added.bone = bone_along_chain(a, b, *centre, options, [&](const std::string& bone) {
              return bone_tree(bone).closest_point(*centre).squared_distance;
            });
            added.position = *centre;
            added.kind = PathPointKind::kFollowsLine;
            refined.push_back(std::move(added));
            ++report.points_added;
            split = true;
          }
        }
        refined.push_back(b);
      }
      line.points = std::move(refined);
      if (!split) break;
    }
    report.inside_after = inside_fraction(positions(line), options.sample_step_mm, inside);
    reports.push_back(report);
  }
  return reports;
}

}  // namespace mmm::atlas

#include "core/wrapping/muscle_penetration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
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

Eigen::Vector3d face_normal(const Eigen::MatrixX3d& x, const Eigen::MatrixX3i& faces, int f) {
  const Eigen::Vector3d a = x.row(faces(f, 0)).transpose();
  const Eigen::Vector3d b = x.row(faces(f, 1)).transpose();
  const Eigen::Vector3d c = x.row(faces(f, 2)).transpose();
  return (b - a).cross(c - a).normalized();
}

// Whether p, whose nearest point of a closed surface is `closest`, is inside
// it: when that point is inside a face, by the side of the face p is on
// (exact); on an edge or a corner, by the winding number.
bool inside(const mesh::SignedDistance& surface, const mesh::AabbTree::ClosestPoint& closest,
            const Eigen::Vector3d& p) {
  constexpr double kInterior = 1e-6;
  if (closest.barycentric.minCoeff() > kInterior) {
    const mesh::IndexedMesh& mesh = surface.tree().mesh();
    return (p - closest.point).dot(face_normal(mesh.V, mesh.F, closest.face)) < 0.0;
  }
  return surface.winding().is_inside(p);
}

// Calls visit(n, v, depth, closest) for every vertex v of x inside another
// muscle n (closest: the nearest point of n's surface). With a finite
// `reach` (mm), only vertices within it of n's surface are looked at (a
// bounded closest-point query first, the inside test after); `record`, when
// given, receives every vertex's clearance from each muscle whose box meets
// x's, and `known`, when given, skips the vertices that have not moved
// further than their clearance since it was recorded.
template <typename Visit>
void for_each_inside(int self, const Eigen::MatrixX3d& x, const MuscleSurfaces& others,
                     const Visit& visit, double reach = std::numeric_limits<double>::infinity(),
                     MuscleClearance* record = nullptr, const MuscleClearance* known = nullptr) {
  const Eigen::AlignedBox3d own = bounds(x);
  Eigen::VectorXd moved;
  if (known != nullptr) moved = (x - known->from).rowwise().norm();
  if (record != nullptr) {
    record->from = x;
    record->clearance.clear();
  }
  for (std::size_t n = 0; n < others.size(); ++n) {
    if (static_cast<int>(n) == self || !own.intersects(others.box(n))) continue;
    const mesh::SignedDistance& surface = others.surface(n);
    const Eigen::VectorXd* was = nullptr;
    if (known != nullptr) {
      const auto found = known->clearance.find(static_cast<int>(n));
      if (found != known->clearance.end()) was = &found->second;
    }
    Eigen::VectorXd* clearance = nullptr;
    if (record != nullptr) {
      clearance = &record->clearance[static_cast<int>(n)];
      clearance->resize(x.rows());
    }
    for (Eigen::Index v = 0; v < x.rows(); ++v) {
      const Eigen::Vector3d p = x.row(v).transpose();
      if (clearance != nullptr) (*clearance)[v] = others.box(n).exteriorDistance(p);
      if (was != nullptr && moved[v] < (*was)[v]) continue;
      if (!others.box(n).contains(p)) continue;
      if (std::isfinite(reach)) {
        const std::optional<mesh::AabbTree::ClosestPoint> near =
            surface.tree().closest_point_within(p, reach * reach);
        if (clearance != nullptr) (*clearance)[v] = reach;
        if (!near) continue;
        const bool in = inside(surface, *near, p);
        if (clearance != nullptr) (*clearance)[v] = in ? 0.0 : std::sqrt(near->squared_distance);
        if (!in) continue;
        visit(static_cast<int>(n), v, std::sqrt(near->squared_distance), *near);
        continue;
      }
      if (!surface.winding().is_inside(p)) continue;
      const mesh::AabbTree::ClosestPoint closest = surface.tree().closest_point(p);
      visit(static_cast<int>(n), v, std::sqrt(closest.squared_distance), closest);
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
  for_each_inside(
      self, x, others,
      [&](int n, Eigen::Index v, double depth, const mesh::AabbTree::ClosestPoint& /*closest*/) {
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
  for_each_inside(
      self, x, others,
      [&](int n, Eigen::Index v, double depth, const mesh::AabbTree::ClosestPoint& /*closest*/) {
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

std::vector<std::vector<Contact>> shared_muscle_contacts(
    const std::vector<Eigen::MatrixX3d>& positions, const MuscleSurfaces& surfaces,
    const MuscleContactOptions& options, int threads, std::vector<MuscleClearance>* clearances) {
  if (clearances != nullptr) clearances->assign(positions.size(), MuscleClearance{});
  const double share = options.share;
  if (!(share >= 0.0 && share <= 1.0))
    throw InvalidInputError("muscle contacts: the share must be in [0, 1], not " +
                            std::to_string(share));
  const std::size_t muscles = positions.size();
  if (muscles != surfaces.size()) {
    throw InvalidInputError("muscle contacts: " + std::to_string(muscles) + " vertex sets for " +
                            std::to_string(surfaces.size()) + " surfaces");
  }
  struct Pin {
    std::size_t muscle;
    Eigen::Index vertex;
    Eigen::Vector3d move;
    int obstacle;
  };
  std::vector<std::vector<Pin>> pins(muscles);  // found from each muscle's vertices
  parallel_for(muscles, threads, [&](std::size_t m) {
    const Eigen::MatrixX3d& x = positions[m];
    for_each_inside(
        static_cast<int>(m), x, surfaces,
        [&](int n, Eigen::Index v, double depth, const mesh::AabbTree::ClosestPoint& closest) {
          if (depth <= options.tolerance_mm) return;
          // Out along the other surface's normal there: vertices nearest to
          // one of its ridges are not gathered onto the ridge.
          const auto other = static_cast<std::size_t>(n);
          const Eigen::MatrixX3i& faces = surfaces.faces(other);
          const Eigen::Vector3d out = depth * face_normal(positions[other], faces, closest.face);
          pins[m].push_back({m, v, share * out, muscle_obstacle(n)});
          for (int corner = 0; corner < 3; ++corner) {
            pins[m].push_back({other, faces(closest.face, corner), -(1.0 - share) * out,
                               muscle_obstacle(static_cast<int>(m))});
          }
        },
        options.reach_mm, clearances != nullptr ? &(*clearances)[m] : nullptr);
  });
  std::vector<std::map<Eigen::Index, std::pair<Eigen::Vector3d, int>>> longest(muscles);
  for (const std::vector<Pin>& found : pins) {
    for (const Pin& pin : found) {
      auto [entry, added] = longest[pin.muscle].try_emplace(pin.vertex, pin.move, pin.obstacle);
      if (!added && pin.move.squaredNorm() > entry->second.first.squaredNorm())
        entry->second = {pin.move, pin.obstacle};
    }
  }
  std::vector<std::vector<Contact>> contacts(muscles);
  for (std::size_t m = 0; m < muscles; ++m) {
    for (const auto& [vertex, entry] : longest[m]) {
      if (entry.first.squaredNorm() == 0.0) continue;
      const Eigen::Vector3d p = positions[m].row(vertex).transpose();
      contacts[m].push_back(
          {static_cast<int>(vertex), p + entry.first, entry.second, options.weight});
    }
  }
  return contacts;
}

double longest_move(const std::vector<std::vector<Contact>>& found,
                    const std::vector<Eigen::MatrixX3d>& positions) {
  if (found.size() != positions.size()) {
    throw InvalidInputError("muscle contacts: contacts for " + std::to_string(found.size()) +
                            " muscles, positions for " + std::to_string(positions.size()));
  }
  double longest = 0.0;
  for (std::size_t m = 0; m < found.size(); ++m) {
    for (const Contact& contact : found[m]) {
      if (contact.vertex < 0 || contact.vertex >= positions[m].rows()) {
        throw InvalidInputError("muscle contacts: vertex " + std::to_string(contact.vertex) +
                                " of muscle " + std::to_string(m) + " outside its " +
                                std::to_string(positions[m].rows()) + " vertices");
      }
      longest =
          std::max(longest, (contact.target - positions[m].row(contact.vertex).transpose()).norm());
    }
  }
  return longest;
}

double round_share(double share, int round, int rounds) {
  const double first = std::max(share, 1.0 - share);
  if (rounds <= 1) return first;
  return first + (1.0 - first) * std::clamp(round, 0, rounds - 1) / (rounds - 1);
}

bool MusclePins::add(const std::vector<std::vector<Contact>>& found) {
  if (found.size() != pins_.size()) {
    throw InvalidInputError("muscle pins: contacts for " + std::to_string(found.size()) +
                            " muscles, expected " + std::to_string(pins_.size()));
  }
  bool any = false;
  for (std::size_t m = 0; m < found.size(); ++m) {
    for (const Contact& contact : found[m]) pins_[m][contact.vertex] = contact;
    any = any || !found[m].empty();
  }
  return any;
}

std::vector<Contact> MusclePins::of(std::size_t muscle) const {
  std::vector<Contact> contacts;
  contacts.reserve(pins_[muscle].size());
  for (const auto& [vertex, contact] : pins_[muscle]) contacts.push_back(contact);
  return contacts;
}

std::vector<MuscleOverlap> muscle_overlaps(int self, const Eigen::MatrixX3d& x,
                                           const std::vector<char>& active,
                                           const MuscleSurfaces& others,
                                           const MuscleContactOptions& options,
                                           const MuscleClearance* clearance) {
  std::map<Eigen::Index, MuscleOverlap> deepest;  // by vertex
  for_each_inside(
      self, x, others,
      [&](int n, Eigen::Index v, double depth, const mesh::AabbTree::ClosestPoint& closest) {
        if (active[static_cast<std::size_t>(v)] != 0 || depth <= options.tolerance_mm) return;
        const auto found = deepest.find(v);
        if (found != deepest.end() && found->second.depth >= depth) return;
        deepest[v] = {static_cast<int>(v), n,    closest.face, closest.barycentric,
                      closest.point,       depth};
      },
      options.reach_mm, nullptr, clearance);
  std::vector<MuscleOverlap> overlaps;
  overlaps.reserve(deepest.size());
  for (const auto& [vertex, overlap] : deepest) overlaps.push_back(overlap);
  return overlaps;
}

std::vector<Contact> muscle_entries(int self, const Eigen::MatrixX3d& x,
                                    const std::vector<char>& active, const MuscleSurfaces& others,
                                    const MuscleContactOptions& options,
                                    const MuscleClearance* clearance) {
  std::vector<Contact> contacts;
  for (const MuscleOverlap& overlap : muscle_overlaps(self, x, active, others, options, clearance))
    contacts.push_back(
        {overlap.vertex, overlap.point, muscle_obstacle(overlap.other), options.weight});
  return contacts;
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

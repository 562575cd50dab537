#include "core/atlas/limb_envelope.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"

namespace mmm::atlas {
namespace {

using Eigen::Vector2d;

double cross(const Vector2d& o, const Vector2d& a, const Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Andrew's monotone chain: the hull counter-clockwise, no repeated point.
std::vector<Vector2d> convex_hull(std::vector<Vector2d> points) {
  std::ranges::sort(points, [](const Vector2d& a, const Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  std::vector<Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (const Vector2d& p : points) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// Distance from c along unit direction d to the boundary of the convex polygon
// (c inside it).
double reach(const std::vector<Vector2d>& hull, const Vector2d& c, const Vector2d& d) {
  double best = 0.0;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Vector2d a = hull[i] - c;
    const Vector2d e = hull[(i + 1) % hull.size()] - hull[i];
    const double denominator = d.x() * e.y() - d.y() * e.x();
    if (std::abs(denominator) < 1e-12) continue;
    const double t = (a.x() * e.y() - a.y() * e.x()) / denominator;
    const double s = (a.x() * d.y() - a.y() * d.x()) / denominator;
    if (t > 0 && s >= -1e-9 && s <= 1 + 1e-9) best = std::max(best, t);
  }
  return best;
}

}  // namespace

mesh::IndexedMesh limb_envelope(const std::vector<const mesh::IndexedMesh*>& surfaces,
                                const LimbEnvelopeOptions& options) {
  if (surfaces.empty()) throw InvalidInputError("limb envelope: no surface given");
  if (!(options.slice_mm > 0) || options.sectors < 8 || !(options.fat_mm >= 0)) {
    throw InvalidInputError("limb envelope: slice_mm must be > 0, sectors >= 8 and fat_mm >= 0");
  }
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const mesh::IndexedMesh* surface : surfaces) {
    if (surface->V.rows() == 0) continue;
    lo = std::min(lo, surface->V.col(2).minCoeff());
    hi = std::max(hi, surface->V.col(2).maxCoeff());
  }
  if (!std::isfinite(lo)) throw InvalidInputError("limb envelope: the surfaces have no vertex");
  const auto slices = static_cast<int>(std::ceil((hi - lo) / options.slice_mm)) + 1;
  std::vector<std::vector<Vector2d>> slab(static_cast<std::size_t>(slices));
  // Each face's corners go to every slab its z range meets: the slice of a
  // face lies within the hull of its corners' (x, y).
  for (const mesh::IndexedMesh* surface : surfaces) {
    for (Eigen::Index f = 0; f < surface->F.rows(); ++f) {
      double z0 = std::numeric_limits<double>::infinity();
      double z1 = -z0;
      for (int k = 0; k < 3; ++k) {
        const double z = (surface->V(surface->F(f, k), 2) - lo) / options.slice_mm;
        z0 = std::min(z0, z);
        z1 = std::max(z1, z);
      }
      // The slab of slice s spans [s - 1, s + 1] in slice units.
      const int first = std::max(0, static_cast<int>(std::ceil(z0 - 1.0)));
      const int last = std::min(slices - 1, static_cast<int>(std::floor(z1 + 1.0)));
      for (int s = first; s <= last; ++s) {
        for (int k = 0; k < 3; ++k) {
          const Eigen::Index v = surface->F(f, k);
          slab[static_cast<std::size_t>(s)].emplace_back(surface->V(v, 0), surface->V(v, 1));
        }
      }
    }
  }
  const int n = options.sectors;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  std::vector<Eigen::Vector3d> centres;
  // Ring r's vertices are r * n + k; the caps' centres go after all rings.
  std::vector<std::vector<Eigen::Vector3d>> rings;
  std::vector<std::vector<Vector2d>> hulls;  // per ring
  std::vector<std::pair<int, int>> runs;     // [first, last] ring of each run
  bool run_open = false;                     // the previous slice made a ring
  for (int s = 0; s < slices; ++s) {
    const std::vector<Vector2d> hull = convex_hull(slab[static_cast<std::size_t>(s)]);
    if (hull.size() < 3) {
      run_open = false;
      continue;
    }
    Vector2d c = Vector2d::Zero();
    for (const Vector2d& p : hull) c += p;
    c /= static_cast<double>(hull.size());
    const double z = lo + s * options.slice_mm;
    std::vector<Eigen::Vector3d> ring;
    for (int k = 0; k < n; ++k) {
      const double angle = 2.0 * std::numbers::pi * k / n;
      const Vector2d d(std::cos(angle), std::sin(angle));
      const Vector2d p = c + (reach(hull, c, d) + options.fat_mm) * d;
      ring.emplace_back(p.x(), p.y(), z);
    }
    rings.push_back(std::move(ring));
    hulls.push_back(hull);
    centres.emplace_back(c.x(), c.y(), z);
    const int r = static_cast<int>(rings.size()) - 1;
    if (run_open) {
      runs.back().second = r;
    } else {
      runs.emplace_back(r, r);
    }
    run_open = true;
  }
  // Smoothed along z within each run (weights 1 2 3 2 1 over five rings), so
  // that the body has no steps where a slice's hull changes abruptly; never
  // closer than half the fat to the slice's own hull.
  for (const auto& [first, last] : runs) {
    std::vector<std::vector<Eigen::Vector3d>> smoothed;
    std::vector<Eigen::Vector3d> smoothed_centres;
    for (int r = first; r <= last; ++r) {
      std::vector<Eigen::Vector3d> ring(static_cast<std::size_t>(n), Eigen::Vector3d::Zero());
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      double total = 0.0;
      for (int o = -2; o <= 2; ++o) {
        const int q = std::clamp(r + o, first, last);
        const double w = 3.0 - std::abs(o);
        for (int k = 0; k < n; ++k) {
          ring[static_cast<std::size_t>(k)] +=
              w * rings[static_cast<std::size_t>(q)][static_cast<std::size_t>(k)];
        }
        centre += w * centres[static_cast<std::size_t>(q)];
        total += w;
      }
      centre /= total;
      const double z = rings[static_cast<std::size_t>(r)][0].z();
      const Vector2d c(centre.x(), centre.y());
      const std::vector<Vector2d>& hull = hulls[static_cast<std::size_t>(r)];
      for (int k = 0; k < n; ++k) {
        Eigen::Vector3d& p = ring[static_cast<std::size_t>(k)];
        p /= total;
        const double angle = 2.0 * std::numbers::pi * k / n;
        const Vector2d d(std::cos(angle), std::sin(angle));
        const double least = reach(hull, c, d) + 0.5 * options.fat_mm;
        const double radius = std::max((Vector2d(p.x(), p.y()) - c).dot(d), least);
        p = Eigen::Vector3d(c.x() + radius * d.x(), c.y() + radius * d.y(), z);
      }
      smoothed.push_back(std::move(ring));
      smoothed_centres.emplace_back(c.x(), c.y(), z);
    }
    for (int r = first; r <= last; ++r) {
      rings[static_cast<std::size_t>(r)] = std::move(smoothed[static_cast<std::size_t>(r - first)]);
      centres[static_cast<std::size_t>(r)] = smoothed_centres[static_cast<std::size_t>(r - first)];
    }
  }
  for (const auto& ring : rings) vertices.insert(vertices.end(), ring.begin(), ring.end());
  for (const auto& [first, last] : runs) {
    if (first == last) continue;  // one slice alone encloses nothing
    for (int r = first; r < last; ++r) {
      for (int k = 0; k < n; ++k) {
        const int a = r * n + k;
        const int b = r * n + (k + 1) % n;
        const int c = (r + 1) * n + k;
        const int d = (r + 1) * n + (k + 1) % n;
        faces.emplace_back(a, b, d);
        faces.emplace_back(a, d, c);
      }
    }
    // Caps: a fan to the first ring's centre below, to the last one's above.
    const auto bottom = static_cast<int>(vertices.size());
    vertices.push_back(centres[static_cast<std::size_t>(first)]);
    const auto top = static_cast<int>(vertices.size());
    vertices.push_back(centres[static_cast<std::size_t>(last)]);
    for (int k = 0; k < n; ++k) {
      faces.emplace_back(bottom, first * n + (k + 1) % n, first * n + k);
      faces.emplace_back(top, last * n + k, last * n + (k + 1) % n);
    }
  }
  mesh::IndexedMesh out;
  out.V.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    out.V.row(static_cast<Eigen::Index>(i)) = vertices[i].transpose();
  }
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    out.F.row(static_cast<Eigen::Index>(i)) = faces[i].transpose();
  }
  if (mesh::signed_volume(out) < 0) out.F.col(1).swap(out.F.col(2));
  return out;
}

}  // namespace mmm::atlas

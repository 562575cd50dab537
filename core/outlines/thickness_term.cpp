#include "core/outlines/thickness_term.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace mmm::outlines {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

struct Crossing {
  int face = 0;
  Vector3d barycentric = Vector3d::Zero();
  Vector3d point = Vector3d::Zero();
  Vector3d normal = Vector3d::Zero();  // unit, outward
  double cosine = 0.0;                 // normal . direction
};

struct Sample {
  double u = 0.0;
  double length = 0.0;  // mm inside the surface
  bool usable = false;  // every crossing steep enough, entries and exits alternating
  std::vector<Crossing> crossings;
};

Sample cast(const mesh::AabbTree& tree, const image::RadiographView& view, double u, double v,
            double min_cosine) {
  Sample sample;
  sample.u = u;
  const image::Ray ray = image::backproject(view, {u, v});
  const std::vector<mesh::AabbTree::RayHit> hits = tree.all_hits(ray.origin, ray.direction);
  const mesh::IndexedMesh& surface = tree.mesh();
  bool inside = false;
  double opened = 0.0;
  sample.usable = true;
  for (const mesh::AabbTree::RayHit& hit : hits) {
    const Vector3d a = surface.V.row(surface.F(hit.face, 0)).transpose();
    const Vector3d b = surface.V.row(surface.F(hit.face, 1)).transpose();
    const Vector3d c = surface.V.row(surface.F(hit.face, 2)).transpose();
    const Vector3d normal = (b - a).cross(c - a).normalized();
    const double cosine = normal.dot(ray.direction);
    const bool entering = cosine < 0;
    if (entering == inside || std::abs(cosine) < min_cosine) sample.usable = false;
    if (entering) {
      opened = hit.t;
    } else {
      sample.length += hit.t - opened;
    }
    inside = entering;
    sample.crossings.push_back(
        {hit.face, hit.barycentric, ray.origin + hit.t * ray.direction, normal, cosine});
  }
  if (inside) sample.usable = false;
  return sample;
}

}  // namespace

ThicknessRows thickness_rows(const mesh::AabbTree& tree, const Eigen::MatrixX3d& rest,
                             const NodeWeights& weights, const Vector3d& centre,
                             const ThicknessView& view, const ThicknessOptions& options,
                             double& gain) {
  ThicknessRows out;
  const mesh::IndexedMesh& current = tree.mesh();
  const image::RadiographView& geometry = *view.view;
  const double spacing = geometry.pixel_spacing_mm;
  const double step = options.step_mm / spacing;
  const double margin = options.margin_mm / spacing;
  double lo_u = geometry.width;
  double lo_v = geometry.height;
  double hi_u = 0.0;
  double hi_v = 0.0;
  for (Eigen::Index i = 0; i < current.V.rows(); ++i) {
    const Vector2d p = image::project(geometry, current.V.row(i).transpose());
    lo_u = std::min(lo_u, p.x());
    lo_v = std::min(lo_v, p.y());
    hi_u = std::max(hi_u, p.x());
    hi_v = std::max(hi_v, p.y());
  }
  const auto other_bone_at = [&](int x, int y) {
    if (view.cover == nullptr) return false;
    const int count =
        (*view.cover)[static_cast<std::size_t>(y) * static_cast<std::size_t>(geometry.width) +
                      static_cast<std::size_t>(x)];
    const int own = view.own != nullptr && view.own->covered(x, y) ? 1 : 0;
    return count - own > 0;
  };

  // Sample rays over the current projection, one image row after the other.
  std::vector<std::vector<Sample>> grid;
  std::vector<double> grid_v;
  for (double v = lo_v + 0.5 * step; v < hi_v; v += step) {
    std::vector<Sample> line;
    for (double u = lo_u + 0.5 * step; u < hi_u; u += step) {
      line.push_back(cast(tree, geometry, u, v, options.min_cosine));
    }
    grid.push_back(std::move(line));
    grid_v.push_back(v);
  }
  const auto inside_image = [&](double u, double v) {
    return u >= 1.0 && v >= 1.0 && u <= geometry.width - 1.0 && v <= geometry.height - 1.0;
  };
  const bool soft = view.soft != nullptr && view.soft->usable();
  const auto soft_at = [&](double u, double v) { return soft ? view.soft->at({u, v}) : 0.0; };
  // What the image says: the excess over the row's background, per sample.
  std::vector<std::pair<double, const Sample*>> kept;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const std::vector<Sample>& line = grid[i];
    const double v = grid_v[i];
    const int row = static_cast<int>(std::floor(v));
    const auto first = std::ranges::find_if(line, [](const Sample& s) { return s.length > 0; });
    if (first == line.end()) continue;
    const auto last = std::ranges::find_if(line.rbegin(), line.rend(),
                                           [](const Sample& s) { return s.length > 0; });
    const double left = first->u - step - margin;
    const double right = last->u + step + margin;
    if (!inside_image(left, v) || !inside_image(right, v)) continue;
    bool crossed = false;
    for (int x = static_cast<int>(std::floor(left)) - 1;
         x <= static_cast<int>(std::ceil(right)) + 1 && !crossed; ++x) {
      crossed = x >= 0 && x < geometry.width && other_bone_at(x, row);
    }
    if (crossed || (soft && !view.soft->holds(v))) continue;
    const double background_left = view.image->sample({left, v}) - soft_at(left, v);
    const double background_right = view.image->sample({right, v}) - soft_at(right, v);
    for (const Sample& sample : line) {
      if (!sample.usable || sample.length <= 0) continue;
      const double t = (sample.u - left) / (right - left);
      const double background =
          (1.0 - t) * background_left + t * background_right + soft_at(sample.u, v);
      kept.emplace_back(view.image->sample({sample.u, v}) - background, &sample);
    }
  }
  if (kept.empty()) return out;
  if (!(gain > 0)) {
    // The median ratio over the rays through most bone (at least half the
    // longest): robust to rows whose background is off and to the thin rims
    // where the model's outline is not yet the image's.
    double longest = 0.0;
    for (const auto& [excess, sample] : kept) longest = std::max(longest, sample->length);
    std::vector<double> ratios;
    for (const auto& [excess, sample] : kept) {
      if (sample->length >= 0.5 * longest) ratios.push_back(excess / sample->length);
    }
    const auto middle = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
    std::ranges::nth_element(ratios, middle);
    gain = *middle;
    if (!(gain > 0)) return out;  // no bone brighter than its surroundings: nothing to use
  }
  for (const auto& [excess, sample] : kept) {
    const double residual = excess / gain - sample->length;
    const double magnitude = std::abs(residual);
    // Huber within robust_mm; beyond cutoff * robust_mm the sample is left
    // out (an overlap the covers missed, a background across an edge).
    if (magnitude > options.cutoff * options.robust_mm) continue;
    FitRow row;
    double fixed = 0.0;
    double current_value = 0.0;
    for (const Crossing& crossing : sample->crossings) {
      const Vector3d a = crossing.normal / std::abs(crossing.cosine);
      current_value += a.dot(crossing.point);
      for (int corner = 0; corner < 3; ++corner) {
        const int vertex = current.F(crossing.face, corner);
        fixed += add_point(row, a, rest.row(vertex).transpose(), centre,
                           weights[static_cast<std::size_t>(vertex)], crossing.barycentric[corner]);
      }
    }
    row.value = current_value + residual - fixed;
    row.weight =
        options.weight * (magnitude <= options.robust_mm ? 1.0 : options.robust_mm / magnitude);
    out.rows.push_back(std::move(row));
    out.residual_mm.push_back(magnitude);
  }
  return out;
}

}  // namespace mmm::outlines

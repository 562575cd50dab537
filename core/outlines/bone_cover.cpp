#include "core/outlines/bone_cover.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace mmm::outlines {
namespace {

double edge_function(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

}  // namespace

BoneCover::BoneCover(const mesh::IndexedMesh& surface, const image::RadiographView& view) {
  const Eigen::Index n = surface.V.rows();
  std::vector<Eigen::Vector2d> pixel(static_cast<std::size_t>(n));
  std::vector<bool> in_front(static_cast<std::size_t>(n));
  double lo_x = view.width;
  double lo_y = view.height;
  double hi_x = 0.0;
  double hi_y = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d x = surface.V.row(i).transpose();
    const auto k = static_cast<std::size_t>(i);
    in_front[k] = image::depth_mm(view, x) > 0;
    if (!in_front[k]) continue;
    pixel[k] = image::project(view, x);
    lo_x = std::min(lo_x, pixel[k].x());
    lo_y = std::min(lo_y, pixel[k].y());
    hi_x = std::max(hi_x, pixel[k].x());
    hi_y = std::max(hi_y, pixel[k].y());
  }
  x0_ = std::clamp(static_cast<int>(std::floor(lo_x)), 0, view.width);
  y0_ = std::clamp(static_cast<int>(std::floor(lo_y)), 0, view.height);
  width_ = std::clamp(static_cast<int>(std::ceil(hi_x)), 0, view.width) - x0_;
  height_ = std::clamp(static_cast<int>(std::ceil(hi_y)), 0, view.height) - y0_;
  if (width_ <= 0 || height_ <= 0) {
    width_ = height_ = 0;
    return;
  }
  inside_.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_), 0);
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    std::array<Eigen::Vector2d, 3> c;
    bool usable = true;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(surface.F(f, k));
      usable = usable && in_front[v];
      c[static_cast<std::size_t>(k)] = pixel[v];
    }
    const double area = edge_function(c[0], c[1], c[2]);
    if (!usable || area == 0.0) continue;
    const int xa =
        std::max(x0_, static_cast<int>(std::floor(std::min({c[0].x(), c[1].x(), c[2].x()}))));
    const int xb = std::min(x0_ + width_ - 1,
                            static_cast<int>(std::ceil(std::max({c[0].x(), c[1].x(), c[2].x()}))));
    const int ya =
        std::max(y0_, static_cast<int>(std::floor(std::min({c[0].y(), c[1].y(), c[2].y()}))));
    const int yb = std::min(y0_ + height_ - 1,
                            static_cast<int>(std::ceil(std::max({c[0].y(), c[1].y(), c[2].y()}))));
    for (int y = ya; y <= yb; ++y) {
      for (int x = xa; x <= xb; ++x) {
        const Eigen::Vector2d p(x + 0.5, y + 0.5);
        const double w0 = edge_function(c[1], c[2], p) / area;
        const double w1 = edge_function(c[2], c[0], p) / area;
        const double w2 = edge_function(c[0], c[1], p) / area;
        if (w0 >= 0 && w1 >= 0 && w2 >= 0) {
          inside_[static_cast<std::size_t>(y - y0_) * static_cast<std::size_t>(width_) +
                  static_cast<std::size_t>(x - x0_)] = 1;
        }
      }
    }
  }
}

bool BoneCover::covered(int x, int y) const {
  if (x < x0_ || y < y0_ || x >= x0_ + width_ || y >= y0_ + height_) return false;
  return inside_[static_cast<std::size_t>(y - y0_) * static_cast<std::size_t>(width_) +
                 static_cast<std::size_t>(x - x0_)] != 0;
}

void BoneCover::add_to(std::vector<std::uint8_t>& counts, int width, int height) const {
  for (int y = std::max(0, y0_); y < std::min(height, y0_ + height_); ++y) {
    for (int x = std::max(0, x0_); x < std::min(width, x0_ + width_); ++x) {
      if (!covered(x, y)) continue;
      std::uint8_t& count = counts[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                                   static_cast<std::size_t>(x)];
      if (count < 255) ++count;
    }
  }
}

std::vector<std::uint8_t> count_cover(const std::vector<const mesh::IndexedMesh*>& surfaces,
                                      const image::RadiographView& view) {
  std::vector<std::uint8_t> counts(
      static_cast<std::size_t>(view.width) * static_cast<std::size_t>(view.height), 0);
  for (const mesh::IndexedMesh* surface : surfaces) {
    BoneCover(*surface, view).add_to(counts, view.width, view.height);
  }
  return counts;
}

}  // namespace mmm::outlines

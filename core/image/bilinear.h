#pragma once
// Bilinear sampling of a single-channel float image at a continuous pixel
// position, with mmm's pixel convention (projection.h): pixel (i, j) has its
// centre at (i + 0.5, j + 0.5). Positions outside are clamped to the border.

#include <Eigen/Core>
#include <algorithm>

#include "core/image/image.h"

namespace mmm::image {

inline double bilinear(const FloatImage& image, const Eigen::Vector2d& pixel) {
  const double x = std::clamp(pixel.x() - 0.5, 0.0, image.width - 1.0);
  const double y = std::clamp(pixel.y() - 0.5, 0.0, image.height - 1.0);
  const int x0 = std::min(static_cast<int>(x), std::max(0, image.width - 2));
  const int y0 = std::min(static_cast<int>(y), std::max(0, image.height - 2));
  const int x1 = std::min(x0 + 1, image.width - 1);
  const int y1 = std::min(y0 + 1, image.height - 1);
  const double fx = x - x0;
  const double fy = y - y0;
  return (1 - fy) * ((1 - fx) * image.at(x0, y0) + fx * image.at(x1, y0)) +
         fy * ((1 - fx) * image.at(x0, y1) + fx * image.at(x1, y1));
}

}  // namespace mmm::image

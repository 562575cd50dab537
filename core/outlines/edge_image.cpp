#include "core/outlines/edge_image.h"

#include "core/image/bilinear.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"

namespace mmm::outlines {
namespace {

int kernel_radius(double sigma) { return std::max(1, static_cast<int>(std::ceil(3.0 * sigma))); }

// Separable Gaussian blur with the kernel cut at 3 sigma, edges clamped.
template <typename Image>
image::FloatImage blurred(const Image& in, double sigma) {
  const int radius = kernel_radius(sigma);
  std::vector<float> kernel(static_cast<std::size_t>(2 * radius + 1));
  double total = 0.0;
  for (std::size_t i = 0; i < kernel.size(); ++i) {
    const double k = static_cast<double>(i) - radius;
    const double w = std::exp(-0.5 * k * k / (sigma * sigma));
    kernel[i] = static_cast<float>(w);
    total += w;
  }
  for (float& w : kernel) w = static_cast<float>(w / total);
  const int w = in.width;
  const int h = in.height;
  image::FloatImage rows(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0.0F;
      for (std::size_t i = 0; i < kernel.size(); ++i) {
        const int xx = std::clamp(x + static_cast<int>(i) - radius, 0, w - 1);
        sum += kernel[i] * static_cast<float>(in.at(xx, y));
      }
      rows.at(x, y) = sum;
    }
  }
  image::FloatImage out(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0.0F;
      for (std::size_t i = 0; i < kernel.size(); ++i) {
        const int yy = std::clamp(y + static_cast<int>(i) - radius, 0, h - 1);
        sum += kernel[i] * rows.at(x, yy);
      }
      out.at(x, y) = sum;
    }
  }
  return out;
}

}  // namespace

EdgeImage::EdgeImage(const image::GrayImage16& radiograph, double sigma_px, double system_blur_px)
    : sigma_px_(sigma_px), edge_shift_px_(kSqrtEdgeShift * std::hypot(sigma_px, system_blur_px)) {
  if (radiograph.empty() || radiograph.pixels.size() != radiograph.sample_count()) {
    throw InvalidInputError(
        "edge image: the radiograph is empty or its pixels do not match its size");
  }
  if (!(sigma_px > 0.0 && sigma_px <= 20.0)) {
    throw InvalidInputError("edge image: smoothing sigma must be in (0, 20] px, got " +
                            std::to_string(sigma_px));
  }
  if (!(system_blur_px >= 0.0 && system_blur_px <= 20.0)) {
    throw InvalidInputError("edge image: the system blur must be in [0, 20] px, got " +
                            std::to_string(system_blur_px));
  }
  const auto smoothed = std::make_shared<const image::FloatImage>(blurred(radiograph, sigma_px));
  smoothed_ = smoothed;
  const image::FloatImage& image = *smoothed;
  // Median gradient magnitude over every 4th pixel of every 4th row.
  std::vector<float> magnitudes;
  for (int y = 1; y + 1 < image.height; y += 4) {
    for (int x = 1; x + 1 < image.width; x += 4) {
      const float gx = 0.5F * (image.at(x + 1, y) - image.at(x - 1, y));
      const float gy = 0.5F * (image.at(x, y + 1) - image.at(x, y - 1));
      magnitudes.push_back(std::sqrt(gx * gx + gy * gy));
    }
  }
  if (!magnitudes.empty()) {
    auto middle = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
    std::nth_element(magnitudes.begin(), middle, magnitudes.end());
    median_gradient_ = *middle;
  }
}

double EdgeImage::sample(const Eigen::Vector2d& pixel) const {
  const double value = image::bilinear(*smoothed_, pixel);
  if (!layer_) return value;
  const Eigen::Vector2d local = pixel - layer_origin_.cast<double>();
  // The padded layer is zero along its border, so clamping reads zero outside.
  return value - image::bilinear(*layer_, local);
}

EdgeImage EdgeImage::without(const image::FloatImage& layer, const Eigen::Vector2i& origin) const {
  if (layer.empty() || layer.pixels.size() != layer.sample_count()) {
    throw InvalidInputError(
        "edge image: the layer to subtract is empty or does not match its size");
  }
  if (!std::ranges::all_of(layer.pixels, [](float value) { return std::isfinite(value); })) {
    throw InvalidInputError("edge image: the layer to subtract has a non-finite value");
  }
  if (layer_) throw InvalidInputError("edge image: a layer has already been subtracted");
  // Padded by the kernel's radius and one more pixel of zeros, so that the
  // blur spreads beyond the layer and the border stays zero.
  const int pad = kernel_radius(sigma_px_) + 1;
  image::FloatImage padded(layer.width + 2 * pad, layer.height + 2 * pad);
  for (int y = 0; y < layer.height; ++y) {
    for (int x = 0; x < layer.width; ++x) padded.at(x + pad, y + pad) = layer.at(x, y);
  }
  EdgeImage out = *this;
  out.layer_ = std::make_shared<const image::FloatImage>(blurred(padded, sigma_px_));
  out.layer_origin_ = origin - Eigen::Vector2i::Constant(pad);
  return out;
}

std::optional<EdgeImage::Edge> EdgeImage::edge_along(const Eigen::Vector2d& p,
                                                     const Eigen::Vector2d& n, double reach_px,
                                                     double min_fall, double nearness) const {
  if (!(p.x() >= 0 && p.y() >= 0 && p.x() <= width() && p.y() <= height())) return std::nullopt;
  constexpr double kStep = 0.5;
  const int steps = std::max(1, static_cast<int>(std::ceil(reach_px / kStep)));
  std::vector<double> fall(static_cast<std::size_t>(2 * steps + 1));
  // Index of offset k (in steps, -steps..steps) in `fall`.
  const auto at = [steps](int k) {
    const int index = k + steps;
    return static_cast<std::size_t>(index);
  };
  for (int k = -steps; k <= steps; ++k) {
    const double s = k * kStep;
    fall[at(k)] = -(sample(p + (s + kStep) * n) - sample(p + (s - kStep) * n)) / (2 * kStep);
  }
  const double prior_sigma = std::max(reach_px * nearness, 1.0);
  std::optional<int> best;
  double best_score = 0.0;
  for (int k = -steps + 1; k <= steps - 1; ++k) {
    const double f = fall[at(k)];
    if (f < min_fall) continue;
    if (f < fall[at(k - 1)] || f < fall[at(k + 1)]) {
      continue;  // not a local peak
    }
    const double s = k * kStep;
    const double score = f * std::exp(-0.5 * s * s / (prior_sigma * prior_sigma));
    if (score > best_score) {
      best_score = score;
      best = k;
    }
  }
  if (!best) return std::nullopt;
  const double a = fall[at(*best - 1)];
  const double b = fall[at(*best)];
  const double c = fall[at(*best + 1)];
  const double curvature = a - 2 * b + c;
  const double shift = curvature < 0 ? std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5) : 0.0;
  return Edge{(*best + shift) * kStep + edge_shift_px_, b};
}

}  // namespace mmm::outlines

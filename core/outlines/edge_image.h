#pragma once
// A radiograph prepared for edge search: the image smoothed by a Gaussian
// and sampled bilinearly, so that intensity profiles along any direction can
// be read at sub-pixel positions.
//
// Radiographs in mmm show attenuation (bone bright, air dark), so walking
// outward across a bone's edge the intensity falls. edge_along() reads the
// profile f(s) = I(p + s n) for s in [-reach, reach] (pixels, step 0.5) and
// returns the position of the steepest fall, -f'(s), weighted by a Gaussian
// prior on s (sigma = nearness * reach) so that of two edges the nearer wins; the
// peak is refined by a parabola through its neighbours. An edge is found when
// the fall there is at least `min_fall` (image units per pixel).
//
// Where the steepest fall lies is not where the edge is. Near the silhouette
// of any smooth body the ray's chord through it grows as the square root of
// the distance inside (c sqrt(d), whatever the curvature), and the steepest
// fall of that profile blurred by a Gaussian of sigma lies kSqrtEdgeShift
// sigma inside the edge (0.73, found numerically; a blur-independent law, so
// one constant serves every bone). The blur is the smoothing's and the
// imaging system's together, sqrt(sigma^2 + system_blur^2); the edge returned
// is the fall's position moved outward by that much.
//
// without() gives the same image less a layer (image units, e.g. the
// fitted neighbouring bones' share of the radiograph), smoothed alike: the
// smoothing is linear, so the layer alone is blurred and subtracted on
// sampling. The two images share the smoothed radiograph.

#include <memory>
#include <optional>

#include <Eigen/Core>

#include "core/image/image.h"

namespace mmm::outlines {

inline constexpr double kSqrtEdgeShift = 0.73;

class EdgeImage {
 public:
  // Throws InvalidInputError for an empty image, sigma outside (0, 20] px or
  // a system blur outside [0, 20] px. system_blur_px: the detector's and
  // sampling's own blur (standard deviation, pixels); 0.4 px is that of an
  // image sampled at pixel centres and read bilinearly.
  EdgeImage(const image::GrayImage16& radiograph, double sigma_px, double system_blur_px = 0.4);

  [[nodiscard]] int width() const { return smoothed_->width; }
  [[nodiscard]] int height() const { return smoothed_->height; }
  [[nodiscard]] double sigma_px() const { return sigma_px_; }
  // Bilinear sample of the smoothed image (less the layer, if any);
  // positions outside are clamped.
  [[nodiscard]] double sample(const Eigen::Vector2d& pixel) const;
  // This image less `layer`, whose pixel (0, 0) is this image's pixel
  // `origin` (zero outside it). The median gradient is this image's. Throws
  // InvalidInputError for an empty layer or a non-finite value in it.
  [[nodiscard]] EdgeImage without(const image::FloatImage& layer,
                                  const Eigen::Vector2i& origin) const;
  // Median over the image of the gradient magnitude (image units per pixel):
  // the scale of noise and texture against which edges are judged.
  [[nodiscard]] double median_gradient() const { return median_gradient_; }

  struct Edge {
    double offset_px = 0.0;  // s of the edge along n (pixels, outward positive; shift applied)
    double fall = 0.0;       // -f'(s) there (image units per pixel)
  };
  // The edge along the unit direction n through p (see the file comment);
  // nothing when p is outside the image or no fall reaches min_fall.
  [[nodiscard]] std::optional<Edge> edge_along(const Eigen::Vector2d& p, const Eigen::Vector2d& n,
                                               double reach_px, double min_fall,
                                               double nearness = 0.5) const;

 private:
  std::shared_ptr<const image::FloatImage> smoothed_;
  // The subtracted layer, smoothed and padded by the kernel's radius; its
  // pixel (0, 0) is the image's pixel layer_origin_.
  std::shared_ptr<const image::FloatImage> layer_;
  Eigen::Vector2i layer_origin_ = Eigen::Vector2i::Zero();
  double sigma_px_ = 1.0;
  double edge_shift_px_ = 0.0;  // kSqrtEdgeShift * total blur
  double median_gradient_ = 0.0;
};

}  // namespace mmm::outlines

#pragma once
// A view's projection fitted to points of known position and their pixels
// (a calibration object, or another model's projections):
//   pinhole  the normalised direct linear transform (Hartley & Zisserman,
//            "Multiple View Geometry", 2nd ed., algorithm 4.2 with the 3-D
//            normalisation of section 7.1): P from the null vector of the
//            2n x 12 system, points and pixels first centred and scaled to
//            unit RMS distance so that the system is well conditioned.
// Used to measure how far a pinhole is from a slot-scanning view (a pinhole
// fitted to an EOS-type scan is exact only at one height and one depth).

#include <Eigen/Core>
#include <cmath>
#include <span>
#include <string>

#include "core/image/projection.h"

namespace mmm::image {

// The similarity taking `points` to their centroid at the origin and an RMS
// distance of sqrt(dimension) (H & Z, section 4.4.4).
template <int D>
Eigen::Matrix<double, D + 1, D + 1> normalising_transform(
    std::span<const Eigen::Matrix<double, D, 1>> points) {
  Eigen::Matrix<double, D, 1> centre = Eigen::Matrix<double, D, 1>::Zero();
  for (const auto& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  double sum_squares = 0;
  for (const auto& p : points) sum_squares += (p - centre).squaredNorm();
  const double rms = std::sqrt(sum_squares / static_cast<double>(points.size()));
  const double scale = rms > 0 ? std::sqrt(static_cast<double>(D)) / rms : 1.0;
  Eigen::Matrix<double, D + 1, D + 1> T = Eigen::Matrix<double, D + 1, D + 1>::Identity();
  T.template topLeftCorner<D, D>() *= scale;
  T.template topRightCorner<D, 1>() = -scale * centre;
  return T;
}

// The pinhole view whose projections of points[i] are nearest pixels[i] in
// the algebraic sense of the DLT; width, height and the pixel spacing at the
// isocentre are the caller's (they are not observed by the points), the
// source is P's centre. Throws InvalidInputError for fewer than 6 points,
// counts that differ, a non-finite value, or points all in one plane (the
// DLT is then degenerate: the fitted P has a singular left block).
RadiographView fit_pinhole_view(std::span<const Eigen::Vector3d> points,
                                std::span<const Eigen::Vector2d> pixels, const std::string& name,
                                int width, int height, double pixel_spacing_mm);

}  // namespace mmm::image

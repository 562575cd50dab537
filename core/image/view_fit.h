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
#include <span>
#include <string>

#include "core/image/projection.h"

namespace mmm::image {

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

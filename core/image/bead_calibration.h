#pragma once
// Calibration of one radiograph view from a calibration object: beads of
// known 3-D position (mm, the object's frame, which becomes the world frame)
// seen at known pixels (placed by an operator, then refined by
// refine_bead_pixel).
//
//   linear start  pinhole: normalised DLT (view_fit.h). Slot scanning: row
//                 1 (v = p2 . [X 1]) by linear least squares, rows 0 and 2
//                 (u (p3 . [X 1]) = p1 . [X 1]) as the null vector of the
//                 normalised homogeneous system.
//   refinement    Ceres (Levenberg-Marquardt) on the 12 entries of P,
//                 residuals the reprojection errors in pixels times the
//                 spacing at the beads' centre (mm).
//   report        per bead: its reprojection error (mm at the beads'
//                 centre); RMS and maximum; whether Ceres converged.
//
// A view has 11 (pinhole) or 11 (slot scanning: 7 + 4) degrees of freedom;
// 6 beads not in one plane are the least, 12 or more spread over the
// field and in depth are advised.

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "core/image/image.h"
#include "core/image/projection.h"

namespace mmm::image {

struct BeadPixel {
  std::string bead;             // name, for the report
  Eigen::Vector3d position_mm;  // known position on the calibration object
  Eigen::Vector2d pixel;        // where it is seen
};

struct BeadResidual {
  std::string bead;
  Eigen::Vector2d pixel;      // observed
  Eigen::Vector2d projected;  // by the calibrated view
  double error_mm = 0.0;      // |projected - pixel| x spacing
};

struct BeadCalibration {
  RadiographView view;
  std::vector<BeadResidual> residuals;  // in the input order
  double rms_mm = 0.0;
  double max_mm = 0.0;
  bool converged = false;
  std::string solver_report;
};

// Calibrates view `name` of `width` x `height` pixels with `model`. The
// pixel spacing of the result is the one at the beads' centroid. Throws
// InvalidInputError naming the bead for fewer than 6 beads, a non-finite
// value, a repeated bead name, or beads whose geometry does not determine
// the view (all in one plane, or the fit degenerate); SolverError when
// Ceres fails.
BeadCalibration calibrate_view_from_beads(const std::string& name, int width, int height,
                                          ProjectionModel model, std::span<const BeadPixel> beads);

// The bead's centre near `approximate` (pixels): the centroid of the image's
// excess over the median of the ring of radius 1.5 x `radius_px`, within
// `radius_px` of the approximate position. Beads attenuate, so they are
// bright. Returns `approximate` when there is no excess (nothing there).
// Throws InvalidInputError for a position outside the image or a radius
// < 1 or > 100 pixels.
Eigen::Vector2d refine_bead_pixel(const GrayImage16& image, const Eigen::Vector2d& approximate,
                                  double radius_px);

}  // namespace mmm::image

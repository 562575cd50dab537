#include "core/image/bead_calibration.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "core/errors.h"
#include "core/image/view_fit.h"

namespace mmm::image {
namespace {

// Reprojection residual of one bead, in mm (pixels x spacing).
struct BeadResidualCost {
  Eigen::Vector3d X;
  Eigen::Vector2d pixel;
  double spacing;
  bool slot;

  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    std::array<T, 3> h;
    for (std::size_t r = 0; r < 3; ++r) {
      h[r] = p[4 * r] * X.x() + p[4 * r + 1] * X.y() + p[4 * r + 2] * X.z() + p[4 * r + 3];
    }
    if (ceres::abs(h[2]) < T(1e-12)) return false;
    residual[0] = (h[0] / h[2] - pixel.x()) * spacing;
    residual[1] = ((slot ? h[1] : h[1] / h[2]) - pixel.y()) * spacing;
    return true;
  }
};

// The linear start of a slot-scanning view (see the header).
Eigen::Matrix<double, 3, 4> slot_start(std::span<const BeadPixel> beads) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (const BeadPixel& bead : beads) {
    points.push_back(bead.position_mm);
    pixels.push_back(bead.pixel);
  }
  const Eigen::Matrix4d T = normalising_transform<3>(std::span<const Eigen::Vector3d>(points));
  const auto n = static_cast<Eigen::Index>(beads.size());
  // Row 1: v = q . (T [X 1]) in least squares, then p2 = q T.
  Eigen::MatrixXd A(n, 4);
  Eigen::VectorXd b(n);
  // Rows 0 and 2 on u alone: u (r . Y) - s . Y = 0 with Y = T [X 1] and the
  // pixels' u normalised by (u - c) / k.
  double u_centre = 0;
  for (const auto& p : pixels) u_centre += p.x();
  u_centre /= static_cast<double>(n);
  double u_spread = 0;
  for (const auto& p : pixels) u_spread += (p.x() - u_centre) * (p.x() - u_centre);
  u_spread = std::sqrt(u_spread / static_cast<double>(n));
  if (!(u_spread > 0)) u_spread = 1.0;
  Eigen::MatrixXd H(n, 8);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Eigen::RowVector4d Y = (T * points[k].homogeneous()).transpose();
    A.row(i) = Y;
    b(i) = pixels[k].y();
    const double u = (pixels[k].x() - u_centre) / u_spread;
    H.row(i) << -Y, u * Y;
  }
  const Eigen::RowVector4d q = A.colPivHouseholderQr().solve(b).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(H, Eigen::ComputeFullV);
  const Eigen::VectorXd null = svd.matrixV().col(7);
  Eigen::Matrix<double, 3, 4> P;
  // u = k u' + c with u' = s . Y / r . Y: row 0 = k s + c r, row 2 = r.
  const Eigen::RowVector4d s = null.head<4>().transpose();
  const Eigen::RowVector4d r = null.tail<4>().transpose();
  P.row(0) = (u_spread * s + u_centre * r) * T;
  P.row(1) = q * T;
  P.row(2) = r * T;
  // Row 2's scale is free: unit normal, as for a pinhole's depth row.
  const double norm = P.block<1, 3>(2, 0).norm();
  P.row(0) /= norm;
  P.row(2) /= norm;
  return P;
}

}  // namespace

BeadCalibration calibrate_view_from_beads(const std::string& name, int width, int height,
                                          ProjectionModel model, std::span<const BeadPixel> beads) {
  if (beads.size() < 6) {
    throw InvalidInputError("bead calibration of view '" + name +
                            "': " + std::to_string(beads.size()) +
                            " beads; at least 6 not in one plane are needed (12 or more advised)");
  }
  if (width < 1 || height < 1) {
    throw InvalidInputError("bead calibration of view '" + name + "': the image size must be >= 1");
  }
  std::set<std::string> names;
  for (const BeadPixel& bead : beads) {
    if (!bead.position_mm.allFinite() || !bead.pixel.allFinite()) {
      throw InvalidInputError("bead calibration of view '" + name + "': bead '" + bead.bead +
                              "' has a non-finite position or pixel");
    }
    if (!names.insert(bead.bead).second) {
      throw InvalidInputError("bead calibration of view '" + name + "': bead '" + bead.bead +
                              "' is given twice");
    }
  }
  Eigen::Matrix<double, 3, 4> P;
  if (model == ProjectionModel::kPinhole) {
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
    for (const BeadPixel& bead : beads) {
      points.push_back(bead.position_mm);
      pixels.push_back(bead.pixel);
    }
    P = fit_pinhole_view(points, pixels, name, width, height, 1.0).P;
  } else {
    P = slot_start(beads);
  }
  RadiographView view;
  view.name = name;
  view.model = model;
  view.width = width;
  view.height = height;
  view.pixel_spacing_mm = 1.0;
  const auto degenerate = [&] {
    throw InvalidInputError("bead calibration of view '" + name +
                            "': the beads do not determine the view (in one plane, or on one "
                            "line?); hint: use a calibration object with beads at several depths");
  };
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const BeadPixel& bead : beads) centre += bead.position_mm;
  centre /= static_cast<double>(beads.size());
  const auto finish = [&](const Eigen::Matrix<double, 3, 4>& matrix) {
    view.P = matrix;
    const Eigen::Matrix3d M = view.P.leftCols<3>();
    const double bound = M.row(0).norm() * M.row(1).norm() * M.row(2).norm();
    if (!view.P.allFinite() || !(std::abs(M.determinant()) > 1e-12 * bound)) degenerate();
    // The beads in front of the source. A slot view's rows 0 and 2 come from
    // a null vector of arbitrary sign: negating both keeps u and det M and
    // turns the depth round. (A pinhole's depth test does not change with
    // the sign of P.)
    const double sign = M.determinant() > 0 ? 1.0 : -1.0;
    if (model == ProjectionModel::kSlotScanning &&
        sign * view.P.row(2).dot(centre.homogeneous()) < 0) {
      view.P.row(0) *= -1.0;
      view.P.row(2) *= -1.0;
    }
    view.source_mm = -view.P.leftCols<3>().partialPivLu().solve(view.P.col(3));
    // mm per pixel across the image at the beads' centre.
    view.pixel_spacing_mm = 1.0 / projection_jacobian(view, centre).row(0).norm();
    if (!std::isfinite(view.pixel_spacing_mm) || view.pixel_spacing_mm <= 0) degenerate();
  };
  finish(P);
  P = view.P;

  // P's entries row by row, as the cost reads them.
  using RowMajor34 = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;
  std::array<double, 12> p{};
  Eigen::Map<RowMajor34>(p.data()) = P;
  ceres::Problem problem;
  for (const BeadPixel& bead : beads) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<BeadResidualCost, 2, 12>(
            new BeadResidualCost{bead.position_mm, bead.pixel, view.pixel_spacing_mm,
                                 model == ProjectionModel::kSlotScanning}),
        nullptr, p.data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (summary.termination_type == ceres::FAILURE ||
      summary.termination_type == ceres::USER_FAILURE) {
    throw SolverError("bead calibration of view '" + name + "': " + summary.BriefReport());
  }
  P = Eigen::Map<const RowMajor34>(p.data());
  // Row 2 back to unit length (the pinhole's scale, the slot's u scale).
  const double norm = P.block<1, 3>(2, 0).norm();
  P.row(0) /= norm;
  if (model == ProjectionModel::kPinhole) P.row(1) /= norm;
  P.row(2) /= norm;
  finish(P);
  validate_view(view);

  BeadCalibration result;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.solver_report = summary.BriefReport();
  double sum = 0;
  for (const BeadPixel& bead : beads) {
    BeadResidual residual;
    residual.bead = bead.bead;
    residual.pixel = bead.pixel;
    residual.projected = project(view, bead.position_mm);
    residual.error_mm = (residual.projected - bead.pixel).norm() * view.pixel_spacing_mm;
    sum += residual.error_mm * residual.error_mm;
    result.max_mm = std::max(result.max_mm, residual.error_mm);
    result.residuals.push_back(residual);
  }
  result.rms_mm = std::sqrt(sum / static_cast<double>(beads.size()));
  result.view = std::move(view);
  return result;
}

Eigen::Vector2d refine_bead_pixel(const GrayImage16& image, const Eigen::Vector2d& approximate,
                                  double radius_px) {
  if (!(radius_px >= 1.0 && radius_px <= 100.0)) {
    throw InvalidInputError("refine_bead_pixel: the radius must be 1-100 pixels, got " +
                            std::to_string(radius_px));
  }
  if (!approximate.allFinite() || approximate.x() < 0 || approximate.y() < 0 ||
      approximate.x() > image.width || approximate.y() > image.height) {
    throw InvalidInputError("refine_bead_pixel: the position is outside the " +
                            std::to_string(image.width) + " x " + std::to_string(image.height) +
                            " image");
  }
  const double ring = 1.5 * radius_px;
  const int x0 = std::max(0, static_cast<int>(std::floor(approximate.x() - ring - 1)));
  const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(approximate.x() + ring + 1)));
  const int y0 = std::max(0, static_cast<int>(std::floor(approximate.y() - ring - 1)));
  const int y1 =
      std::min(image.height - 1, static_cast<int>(std::ceil(approximate.y() + ring + 1)));
  std::vector<double> background;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double d = (Eigen::Vector2d(x + 0.5, y + 0.5) - approximate).norm();
      if (d > radius_px && d <= ring + 0.5) background.push_back(image.at(x, y));
    }
  }
  if (background.empty()) return approximate;
  std::nth_element(background.begin(),
                   background.begin() + static_cast<std::ptrdiff_t>(background.size() / 2),
                   background.end());
  const double level = background[background.size() / 2];
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double weight = 0;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const Eigen::Vector2d centre(x + 0.5, y + 0.5);
      if ((centre - approximate).norm() > radius_px) continue;
      const double excess = image.at(x, y) - level;
      if (excess <= 0) continue;
      sum += excess * centre;
      weight += excess;
    }
  }
  return weight > 0 ? Eigen::Vector2d(sum / weight) : approximate;
}

}  // namespace mmm::image

#include "core/image/view_fit.h"

#include <Eigen/Dense>
#include <cmath>

#include "core/errors.h"

namespace mmm::image {

RadiographView fit_pinhole_view(std::span<const Eigen::Vector3d> points,
                                std::span<const Eigen::Vector2d> pixels, const std::string& name,
                                int width, int height, double pixel_spacing_mm) {
  if (points.size() != pixels.size()) {
    throw InvalidInputError("fit_pinhole_view: " + std::to_string(points.size()) + " points but " +
                            std::to_string(pixels.size()) + " pixels");
  }
  if (points.size() < 6) {
    throw InvalidInputError("fit_pinhole_view needs at least 6 points (11 unknowns), got " +
                            std::to_string(points.size()));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite() || !pixels[i].allFinite()) {
      throw InvalidInputError("fit_pinhole_view: point " + std::to_string(i) +
                              " or its pixel is not finite");
    }
  }
  const Eigen::Matrix4d T = normalising_transform<3>(points);
  const Eigen::Matrix3d N = normalising_transform<2>(pixels);
  const auto n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd A(2 * n, 12);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Eigen::RowVector4d X = (T * points[k].homogeneous()).transpose();
    const Eigen::Vector2d x = (N * pixels[k].homogeneous()).hnormalized();
    // u (p3 . X) - p1 . X = 0 and v (p3 . X) - p2 . X = 0.
    A.row(2 * i) << -X, Eigen::RowVector4d::Zero(), x.x() * X;
    A.row(2 * i + 1) << Eigen::RowVector4d::Zero(), -X, x.y() * X;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd p = svd.matrixV().col(11);
  Eigen::Matrix<double, 3, 4> normalised;
  normalised << p.segment<4>(0).transpose(), p.segment<4>(4).transpose(),
      p.segment<4>(8).transpose();
  RadiographView view;
  view.name = name;
  view.width = width;
  view.height = height;
  view.pixel_spacing_mm = pixel_spacing_mm;
  view.P = N.inverse() * normalised * T;
  const Eigen::Matrix3d M = view.P.leftCols<3>();
  const double bound = M.row(0).norm() * M.row(1).norm() * M.row(2).norm();
  if (!(std::abs(M.determinant()) > 1e-12 * bound)) {
    throw InvalidInputError(
        "fit_pinhole_view: degenerate fit (the points lie in one plane or on one line); "
        "hint: use points spread in depth as well as across the image");
  }
  view.P /= view.P.block<1, 3>(2, 0).norm();
  view.source_mm = -view.P.leftCols<3>().partialPivLu().solve(view.P.col(3));
  validate_view(view);
  return view;
}

}  // namespace mmm::image

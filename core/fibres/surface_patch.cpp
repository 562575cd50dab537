#include "core/fibres/surface_patch.h"

#include <string>

#include "core/errors.h"

namespace mmm::fibres {

Eigen::MatrixXd natural_cubic_spline(const Eigen::MatrixXd& points, int count) {
  const Eigen::Index k = points.rows();
  if (k < 2 || points.cols() < 3 || count < 2) {
    throw InvalidInputError(
        "cubic spline: needs at least two points of x y z and two samples, got " +
        std::to_string(k) + " points, " + std::to_string(count) + " samples");
  }
  if (!points.allFinite()) throw InvalidInputError("cubic spline: points are not finite");
  const Eigen::MatrixXd p = points.leftCols<3>();
  Eigen::VectorXd u(k);  // knots: chord length, then 0..1
  u[0] = 0.0;
  for (Eigen::Index i = 1; i < k; ++i) {
    const double step = (p.row(i) - p.row(i - 1)).norm();
    if (!(step > 0.0)) {
      throw InvalidInputError("cubic spline: points " + std::to_string(i - 1) + " and " +
                              std::to_string(i) + " coincide");
    }
    u[i] = u[i - 1] + step;
  }
  u /= u[k - 1];
  // Second derivatives M (natural: M_0 = M_k-1 = 0) from the tridiagonal
  // system h_i-1 M_i-1 + 2 (h_i-1 + h_i) M_i + h_i M_i+1 = 6 (slope_i - slope_i-1).
  Eigen::MatrixXd second = Eigen::MatrixXd::Zero(k, 3);
  if (k > 2) {
    const Eigen::Index m = k - 2;
    Eigen::VectorXd diagonal(m);
    Eigen::VectorXd upper(m);
    Eigen::MatrixXd rhs(m, 3);
    for (Eigen::Index i = 1; i <= m; ++i) {
      const double before = u[i] - u[i - 1];
      const double after = u[i + 1] - u[i];
      diagonal[i - 1] = 2.0 * (before + after);
      upper[i - 1] = after;
      rhs.row(i - 1) =
          6.0 * ((p.row(i + 1) - p.row(i)) / after - (p.row(i) - p.row(i - 1)) / before);
    }
    // Thomas algorithm (symmetric: the lower diagonal equals the upper one shifted).
    for (Eigen::Index i = 1; i < m; ++i) {
      const double factor = upper[i - 1] / diagonal[i - 1];
      diagonal[i] -= factor * upper[i - 1];
      rhs.row(i) -= factor * rhs.row(i - 1);
    }
    second.row(m) = rhs.row(m - 1) / diagonal[m - 1];
    for (Eigen::Index i = m - 2; i >= 0; --i)
      second.row(i + 1) = (rhs.row(i) - upper[i] * second.row(i + 2)) / diagonal[i];
  }
  Eigen::MatrixXd samples(count, 3);
  Eigen::Index segment = 0;
  for (int s = 0; s < count; ++s) {
    const double x = static_cast<double>(s) / (count - 1);
    while (segment + 2 < k && x > u[segment + 1]) ++segment;
    const double h = u[segment + 1] - u[segment];
    const double a = (u[segment + 1] - x) / h;
    const double b = (x - u[segment]) / h;
    samples.row(s) =
        a * p.row(segment) + b * p.row(segment + 1) +
        ((a * a * a - a) * second.row(segment) + (b * b * b - b) * second.row(segment + 1)) *
            (h * h / 6.0);
  }
  return samples;
}

mesh::IndexedMesh fibre_surface_patch(const std::vector<TPolynomial>& fibres, int along,
                                      int across) {
  if (fibres.size() < 2 || along < 2 || across < 2) {
    throw InvalidInputError("surface patch: needs at least two fibres, along >= 2 and across >= 2");
  }
  std::vector<Eigen::MatrixXd> sampled;
  sampled.reserve(fibres.size());
  for (std::size_t f = 0; f < fibres.size(); ++f) {
    if (fibres[f].dimensions() < 3) {
      throw InvalidInputError("surface patch: fibre " + std::to_string(f) +
                              " has fewer than three dimensions");
    }
    sampled.push_back(fibres[f].sample(along));
  }
  mesh::IndexedMesh patch;
  patch.V.resize(static_cast<Eigen::Index>(along) * across, 3);
  Eigen::MatrixXd row(static_cast<Eigen::Index>(fibres.size()), 3);
  for (int i = 0; i < along; ++i) {
    for (std::size_t f = 0; f < fibres.size(); ++f)
      row.row(static_cast<Eigen::Index>(f)) = sampled[f].row(i).leftCols<3>();
    patch.V.middleRows(static_cast<Eigen::Index>(i) * across, across) =
        natural_cubic_spline(row, across);
  }
  patch.F.resize(2 * static_cast<Eigen::Index>(along - 1) * (across - 1), 3);
  Eigen::Index f = 0;
  for (int i = 0; i + 1 < along; ++i) {
    for (int j = 0; j + 1 < across; ++j) {
      const int v = i * across + j;
      patch.F.row(f++) << v, v + 1, v + across;
      patch.F.row(f++) << v + 1, v + across + 1, v + across;
    }
  }
  return patch;
}

}  // namespace mmm::fibres

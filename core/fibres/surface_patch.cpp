#include "core/fibres/surface_patch.h"

#include <string>
#include <vector>

#include "core/errors.h"
#include "core/opensim/opensim_function.h"

namespace mmm::fibres {

Eigen::MatrixXd cubic_spline(const Eigen::MatrixXd& points, int count) {
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
  // Per coordinate, the interpolating C2 cubic spline the project already
  // has for OpenSim's SimmSpline (its end conditions reproduce cubics).
  const std::vector<double> knots(u.data(), u.data() + u.size());
  std::vector<opensim::SimmSpline> coordinates;
  coordinates.reserve(3);
  for (int c = 0; c < 3; ++c) {
    const Eigen::VectorXd column = p.col(c);
    coordinates.emplace_back(knots, std::vector<double>(column.data(), column.data() + k));
  }
  Eigen::MatrixXd samples(count, 3);
  for (int s = 0; s < count; ++s) {
    const double x = static_cast<double>(s) / (count - 1);
    for (int c = 0; c < 3; ++c)
      samples(s, c) = coordinates[static_cast<std::size_t>(c)].evaluate(x);
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
    patch.V.middleRows(static_cast<Eigen::Index>(i) * across, across) = cubic_spline(row, across);
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

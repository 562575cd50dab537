#include "core/fit/principal_axes.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"

namespace mmm::fit {
namespace {

// A third moment below this fraction of extent^3 is rounding noise: the shape
// is symmetric about the axis and the moment cannot choose its sign.
constexpr double kSymmetricSkewness = 1e-8;

// Complete homogeneous symmetric polynomial of degree 4 in (x, y, z): the sum
// of all monomials x^i y^j z^k with i + j + k = 4.
double h4(double x, double y, double z) {
  double sum = 0;
  double xi = 1;
  for (int i = 0; i <= 4; ++i, xi *= x) {
    double yj = 1;
    for (int j = 0; j <= 4 - i; ++j, yj *= y) sum += xi * yj * std::pow(z, 4 - i - j);
  }
  return sum;
}

// Integral over the solid of g^3 with g = a.(x - c), by the divergence theorem
// with F = a g^4 / 4: the sum over faces of (a.n) / 4 times the integral of
// g^4 over the triangle, which for g linear is 2 area 4! / 6! h4(g at the
// corners) (exact integration of barycentric monomials).
// Divided by the signed volume, this is E[g^3] per unit volume whatever the
// orientation of the faces.
double solid_third_moment(const mesh::IndexedMesh& m, const Eigen::Vector3d& centroid,
                          double signed_volume, const Eigen::Vector3d& axis) {
  double sum = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)).transpose() - centroid;
    const Eigen::Vector3d b = m.V.row(m.F(f, 1)).transpose() - centroid;
    const Eigen::Vector3d c = m.V.row(m.F(f, 2)).transpose() - centroid;
    const Eigen::Vector3d twice_area_normal = (b - a).cross(c - a);
    sum += axis.dot(twice_area_normal) * h4(axis.dot(a), axis.dot(b), axis.dot(c)) / 120.0;
  }
  return sum / signed_volume;
}

// Eigen-decomposes the covariance and fixes order, signs and handedness.
// third_moment(a) is the shape's E[(a.(x - centroid))^3] for a unit vector a.
template <typename ThirdMoment>
PrincipalAxes from_covariance(const Eigen::Vector3d& centroid, const Eigen::Matrix3d& covariance,
                              const ThirdMoment& third_moment) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  PrincipalAxes out;
  out.centroid = centroid;
  // Eigenvalues come ascending: reverse for long axis first.
  for (int k = 0; k < 3; ++k) {
    out.axes.col(k) = solver.eigenvectors().col(2 - k);
    out.extents[k] = std::sqrt(std::max(0.0, solver.eigenvalues()[2 - k]));
  }
  for (int k = 0; k < 2; ++k) {
    const double cube = std::pow(out.extents[k], 3);
    const double moment = third_moment(Eigen::Vector3d(out.axes.col(k)));
    bool flip = false;
    if (std::abs(moment) > kSymmetricSkewness * cube) {
      flip = moment < 0;
    } else {
      Eigen::Index largest = 0;
      out.axes.col(k).cwiseAbs().maxCoeff(&largest);
      flip = out.axes(largest, k) < 0;
    }
    if (flip) out.axes.col(k) *= -1.0;
  }
  out.axes.col(2) = out.axes.col(0).cross(out.axes.col(1));
  for (int k = 0; k < 3; ++k) {
    const double cube = std::pow(out.extents[k], 3);
    out.skewness[k] = cube > 0 ? third_moment(Eigen::Vector3d(out.axes.col(k))) / cube : 0.0;
  }
  return out;
}

}  // namespace

PrincipalAxes principal_axes(const Eigen::MatrixX3d& points, const Eigen::VectorXd& weights) {
  const Eigen::Index n = points.rows();
  if (weights.size() != 0 && weights.size() != n) {
    throw InvalidInputError("principal_axes: " + std::to_string(weights.size()) + " weights for " +
                            std::to_string(n) + " points");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!points.row(i).allFinite()) {
      throw InvalidInputError("principal_axes: point " + std::to_string(i) + " is not finite");
    }
    if (weights.size() != 0 && !(weights[i] >= 0 && std::isfinite(weights[i]))) {
      throw InvalidInputError("principal_axes: weight " + std::to_string(i) + " is " +
                              std::to_string(weights[i]) + ", expected finite and >= 0");
    }
  }
  Eigen::VectorXd w = weights.size() != 0 ? weights : Eigen::VectorXd::Ones(n);
  const double total = w.sum();
  if (!(total > 0)) {
    throw InvalidInputError("principal_axes: no point with positive weight (" + std::to_string(n) +
                            " points)");
  }
  w /= total;
  const Eigen::Vector3d centroid = points.transpose() * w;
  const Eigen::MatrixX3d centred = points.rowwise() - centroid.transpose();
  const Eigen::Matrix3d covariance = centred.transpose() * w.asDiagonal() * centred;
  return from_covariance(centroid, covariance, [&](const Eigen::Vector3d& axis) {
    return w.dot((centred * axis).array().cube().matrix());
  });
}

PrincipalAxes principal_axes(const mesh::IndexedMesh& closed_mesh) {
  const mesh::MassProperties properties = mesh::mass_properties(closed_mesh);
  const mesh::MeshCheckReport check = mesh::check_mesh(closed_mesh);
  if (!check.closed() || !check.orientation_consistent()) {
    std::string problems;
    for (const std::string& problem : check.problems()) problems += "; " + problem;
    throw InvalidInputError(
        "principal_axes: the mesh does not bound a volume (needs every edge on two faces, "
        "consistently oriented)" +
        problems + "; hint: close it, or take the principal axes of its vertices");
  }
  if (!properties.solid) {
    throw InvalidInputError(
        "principal_axes: the mesh encloses no volume (open or flat surface, volume " +
        std::to_string(properties.volume) +
        " mm^3); hint: close it, or take the principal axes of its vertices");
  }
  const Eigen::Matrix3d covariance = properties.second_moment / std::abs(properties.volume);
  return from_covariance(properties.centroid, covariance, [&](const Eigen::Vector3d& axis) {
    return solid_third_moment(closed_mesh, properties.centroid, properties.volume, axis);
  });
}

}  // namespace mmm::fit

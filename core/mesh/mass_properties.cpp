#include "core/mesh/mass_properties.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "core/errors.h"

namespace mmm::mesh {
namespace {

struct FaceCorners {
  Eigen::Vector3d a, b, c;
};

FaceCorners corners(const IndexedMesh& mesh, Eigen::Index f, const Eigen::Vector3d& origin) {
  return {mesh.V.row(mesh.F(f, 0)).transpose() - origin,
          mesh.V.row(mesh.F(f, 1)).transpose() - origin,
          mesh.V.row(mesh.F(f, 2)).transpose() - origin};
}

Eigen::Vector3d reference_point(const IndexedMesh& mesh) { return bounding_box(mesh).center(); }

void require_faces(const IndexedMesh& mesh) {
  if (mesh.empty()) throw InvalidInputError("mesh has no faces");
  validate_indices_and_coordinates(mesh);
}

// Columns of `vectors` sorted by decreasing `values`, made right-handed.
void sort_axes(Eigen::Vector3d& values, Eigen::Matrix3d& vectors) {
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int i, int j) { return values[i] > values[j]; });
  Eigen::Vector3d sorted_values;
  Eigen::Matrix3d sorted_vectors;
  for (int k = 0; k < 3; ++k) {
    sorted_values[k] = values[order[static_cast<size_t>(k)]];
    sorted_vectors.col(k) = vectors.col(order[static_cast<size_t>(k)]);
  }
  if (sorted_vectors.determinant() < 0) sorted_vectors.col(2) *= -1.0;
  values = sorted_values;
  vectors = sorted_vectors;
}

}  // namespace

double surface_area(const IndexedMesh& mesh) {
  double area = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const auto [a, b, c] = corners(mesh, f, Eigen::Vector3d::Zero());
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

double signed_volume(const IndexedMesh& mesh) {
  if (mesh.empty()) return 0;
  const Eigen::Vector3d origin = reference_point(mesh);
  double six_volume = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const auto [a, b, c] = corners(mesh, f, origin);
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

Eigen::AlignedBox3d bounding_box(const IndexedMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) box.extend(mesh.V.row(v).transpose());
  return box;
}

MassProperties mass_properties(const IndexedMesh& mesh) {
  require_faces(mesh);
  const Eigen::Vector3d origin = reference_point(mesh);
  // Canonical covariance of the tetrahedron (0, e1, e2, e3): integral of
  // x x^T over it is (I + 1 1^T) / 120.
  const Eigen::Matrix3d canonical = (Eigen::Matrix3d::Identity() + Eigen::Matrix3d::Ones()) / 120.0;

  MassProperties out;
  double volume = 0;
  Eigen::Vector3d volume_moment = Eigen::Vector3d::Zero();
  Eigen::Matrix3d volume_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d area_moment = Eigen::Vector3d::Zero();
  Eigen::Matrix3d area_covariance = Eigen::Matrix3d::Zero();
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const auto [a, b, c] = corners(mesh, f, origin);
    Eigen::Matrix3d frame;
    frame << a, b, c;
    const double det = frame.determinant();  // 6 x signed tetrahedron volume
    volume += det / 6.0;
    volume_moment += det / 24.0 * (a + b + c);
    volume_covariance += det * frame * canonical * frame.transpose();

    // Surface moments of the triangle: integral of x and x x^T over its area.
    const double area = 0.5 * (b - a).cross(c - a).norm();
    out.area += area;
    area_moment += area / 3.0 * (a + b + c);
    area_covariance += area / 12.0 *
                       (a * a.transpose() + b * b.transpose() + c * c.transpose() +
                        (a + b + c) * (a + b + c).transpose());
  }
  out.volume = volume;

  // A solid needs an enclosed volume that is not negligible against the
  // surface: |V| > 1e-9 * A^(3/2) rules out flat or open sheets whose cone
  // volume is just rounding noise.
  out.solid = std::abs(volume) > 1e-9 * std::pow(out.area, 1.5);
  Eigen::Matrix3d about_centroid;
  if (out.solid) {
    const Eigen::Vector3d c = volume_moment / volume;
    // Flip by the volume's sign so an inward-oriented solid still has a
    // positive semi-definite second moment.
    about_centroid = (volume_covariance - volume * c * c.transpose()) * (volume < 0 ? -1.0 : 1.0);
    out.centroid = origin + c;
  } else {
    const Eigen::Vector3d c =
        out.area > 0 ? Eigen::Vector3d(area_moment / out.area) : Eigen::Vector3d::Zero();
    about_centroid = area_covariance - out.area * c * c.transpose();
    out.centroid = origin + c;
  }
  out.second_moment = about_centroid;

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(about_centroid);
  Eigen::Vector3d spread = solver.eigenvalues();
  Eigen::Matrix3d axes = solver.eigenvectors();
  sort_axes(spread, axes);
  out.principal_axes = axes;
  // Moment of inertia about axis k is the trace minus the spread along k.
  out.principal_moments = Eigen::Vector3d::Constant(spread.sum()) - spread;
  return out;
}

bool OrientedBox::contains(const Eigen::Vector3d& point, double tolerance) const {
  const Eigen::Vector3d local = axes.transpose() * (point - center);
  return (local.array().abs() <= half_extents.array() + tolerance).all();
}

OrientedBox oriented_bounding_box(const IndexedMesh& mesh) {
  const MassProperties properties = mass_properties(mesh);
  OrientedBox box;
  box.axes = properties.principal_axes;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    const Eigen::Vector3d local = box.axes.transpose() * mesh.V.row(v).transpose();
    lo = lo.cwiseMin(local);
    hi = hi.cwiseMax(local);
  }
  box.center = box.axes * (0.5 * (lo + hi));
  box.half_extents = 0.5 * (hi - lo);
  return box;
}

}  // namespace mmm::mesh

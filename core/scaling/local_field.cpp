#include "core/scaling/local_field.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace mmm::scaling {

double wendland_c2(double r) {
  if (r >= 1.0) return 0.0;
  const double s = 1.0 - r;
  return s * s * s * s * (4.0 * r + 1.0);
}

namespace {

// d phi / d r of Wendland's C2 function: -20 r (1 - r)^3.
double wendland_c2_slope(double r) {
  if (r >= 1.0) return 0.0;
  const double s = 1.0 - r;
  return -20.0 * r * s * s * s;
}

}  // namespace

Eigen::Vector3d LocalField::displacement(const Eigen::Vector3d& rest) const {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < centres.size(); ++k) {
    d += wendland_c2((rest - centres[k]).norm() / radii_mm[k]) * coefficients[k];
  }
  return d;
}

Eigen::Matrix3d LocalField::gradient(const Eigen::Vector3d& rest) const {
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < centres.size(); ++k) {
    const Eigen::Vector3d offset = rest - centres[k];
    const double distance = offset.norm();
    if (distance <= 0.0 || distance >= radii_mm[k]) continue;
    const double slope = wendland_c2_slope(distance / radii_mm[k]) / radii_mm[k];
    J += coefficients[k] * (slope * offset / distance).transpose();
  }
  return J;
}

Eigen::MatrixX3d LocalField::displacements(const Eigen::MatrixX3d& V) const {
  Eigen::MatrixX3d out = Eigen::MatrixX3d::Zero(V.rows(), 3);
  if (empty()) return out;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    out.row(i) = displacement(V.row(i).transpose()).transpose();
  }
  return out;
}

LocalField fit_local_field(const std::vector<LocalPoint>& points) {
  double reach = 0.0;
  for (std::size_t j = 0; j < points.size(); ++j) {
    const LocalPoint& point = points[j];
    bool finite = point.rest.allFinite() && point.misfit.allFinite();
    for (const Eigen::Vector3d& sample : point.samples) finite = finite && sample.allFinite();
    if (!finite || !std::isfinite(point.radius_mm) || point.radius_mm < 0.0 ||
        point.samples.size() != point.weights.size()) {
      throw InvalidInputError("local field: point " + std::to_string(j) +
                              " has a non-finite position, misfit or sample, a negative radius, "
                              "or samples and weights of different sizes");
    }
    reach = std::max(reach, point.radius_mm);
  }
  LocalField field;
  if (reach <= 0.0) return field;
  // The conditions: every local point, then the pins within reach of one
  // (a pin within 1 mm of a condition already there, such as a landmark on a
  // joint centre, adds nothing and would make the system singular).
  std::vector<const LocalPoint*> used;
  std::vector<double> radius;
  for (const LocalPoint& point : points) {
    if (point.radius_mm <= 0.0) continue;
    used.push_back(&point);
    radius.push_back(point.radius_mm);
  }
  const std::size_t local_count = used.size();
  for (const LocalPoint& point : points) {
    if (point.radius_mm > 0.0) continue;
    bool near = false;
    bool duplicate = false;
    for (std::size_t k = 0; k < used.size(); ++k) {
      const double distance = (used[k]->rest - point.rest).norm();
      near = near || (k < local_count && distance < radius[k]);
      duplicate = duplicate || distance < 1.0;
    }
    if (!near || duplicate) continue;
    used.push_back(&point);
    radius.push_back(reach);
  }
  const auto n = static_cast<Eigen::Index>(used.size());
  Eigen::MatrixXd Phi(n, n);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3);
  for (Eigen::Index j = 0; j < n; ++j) {
    const LocalPoint& point = *used[static_cast<std::size_t>(j)];
    if (point.radius_mm > 0.0) rhs.row(j) = point.misfit.transpose();
    // Through the samples only when they stand for the point: a point off
    // its surface (a landmark of a welded bone, anchored on the bone it
    // moves with) extrapolates from far samples, whose field at the point's
    // own centre then differs from 1 by more than 20 %; it is evaluated
    // where it is.
    double self = 0.0;
    for (std::size_t i = 0; i < point.samples.size(); ++i) {
      self += point.weights[i] * wendland_c2((point.samples[i] - point.rest).norm() / reach);
    }
    const bool near_samples = !point.samples.empty() && std::abs(self - 1.0) < 0.2;
    for (Eigen::Index k = 0; k < n; ++k) {
      const Eigen::Vector3d& centre = used[static_cast<std::size_t>(k)]->rest;
      const double R = radius[static_cast<std::size_t>(k)];
      if (!near_samples) {
        Phi(j, k) = wendland_c2((point.rest - centre).norm() / R);
        continue;
      }
      double value = 0.0;
      for (std::size_t i = 0; i < point.samples.size(); ++i) {
        value += point.weights[i] * wendland_c2((point.samples[i] - centre).norm() / R);
      }
      Phi(j, k) = value;
    }
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(Phi);
  if (!lu.isInvertible()) {
    throw SolverError(
        "local field: two local landmarks or joint centres coincide; hint: remove the duplicate");
  }
  const Eigen::MatrixXd c = lu.solve(rhs);
  for (Eigen::Index k = 0; k < n; ++k) {
    field.centres.push_back(used[static_cast<std::size_t>(k)]->rest);
    field.radii_mm.push_back(radius[static_cast<std::size_t>(k)]);
    field.coefficients.emplace_back(c.row(k).transpose());
  }
  return field;
}

}  // namespace mmm::scaling

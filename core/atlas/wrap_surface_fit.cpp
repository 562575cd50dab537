#include "core/atlas/wrap_surface_fit.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "core/fit/cylinder_fit.h"
#include "core/fit/ellipsoid_fit.h"
#include "core/fit/sphere_fit.h"

namespace mmm::atlas {
namespace {

// Fewest region vertices a fit is tried on (the fits need 4-9; a region that
// small is a mistake in the recipe rather than a surface).
constexpr int kFewestRegionVertices = 30;

// A unit vector across `axis`: `wanted` made perpendicular to it, or any
// perpendicular when it has no such part.
Eigen::Vector3d across(const Eigen::Vector3d& axis, const std::optional<Eigen::Vector3d>& wanted) {
  if (wanted) {
    const Eigen::Vector3d part = *wanted - wanted->dot(axis) * axis;
    if (part.norm() > 1e-6 * wanted->norm()) return part.normalized();
  }
  return axis.unitOrthogonal();
}

Eigen::MatrixX3d region_vertices(const Eigen::MatrixX3d& vertices,
                                 const WrapSurfaceRegion& region) {
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
    const Eigen::Vector3d offset = vertices.row(i).transpose() - region.centre;
    if (offset.norm() > region.radius_mm) continue;
    if (region.side && offset.dot(*region.side) < 0) continue;
    kept.push_back(i);
  }
  Eigen::MatrixX3d out(static_cast<Eigen::Index>(kept.size()), 3);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    out.row(static_cast<Eigen::Index>(k)) = vertices.row(kept[k]);
  }
  return out;
}

// Where `point` lies against the obstacle along the ray from its centre (a
// cylinder: from its axis, across it): the ray's length and its length over
// the surface's along the same ray (1 on the surface).
struct Radial {
  double length = 0.0;
  double ratio = 0.0;
};

Radial radial(const WrapObstacle& obstacle, const Eigen::Vector3d& point) {
  const Eigen::Vector3d q = obstacle.pose.inverse() * point;
  switch (obstacle.shape) {
    case WrapShape::kSphere:
      return {q.norm(), q.norm() / obstacle.radii.x()};
    case WrapShape::kCylinder:
      return {q.head<2>().norm(), q.head<2>().norm() / obstacle.radii.x()};
    case WrapShape::kEllipsoid:
      return {q.norm(), q.cwiseQuotient(obstacle.radii).norm()};
  }
  return {};
}

// The largest factor the obstacle's size may be multiplied by, about its
// centre, for `point` to lie `clearance` outside: ratio (1 - clearance / length).
double allowed_scale(const WrapObstacle& obstacle, const Eigen::Vector3d& point, double clearance) {
  const Radial r = radial(obstacle, point);
  return r.length > 0 ? r.ratio * (1.0 - clearance / r.length) : 0.0;
}

}  // namespace

double distance_outside(const WrapObstacle& obstacle, const Eigen::Vector3d& point) {
  // length - length / ratio: the ray's part beyond the surface.
  const Radial r = radial(obstacle, point);
  if (r.ratio <= 0) return -obstacle.radii.minCoeff();
  return r.length * (1.0 - 1.0 / r.ratio);
}

WrapObstacle fit_wrap_surface(const std::string& name, const std::string& bone, WrapShape shape,
                              const Eigen::MatrixX3d& bone_vertices,
                              const WrapSurfaceRegion& region,
                              const std::optional<Eigen::Vector3d>& wrap_side,
                              const std::optional<Eigen::Vector3d>& axis_hint,
                              const std::vector<NamedPoint>& outside, double clearance_mm,
                              WrapSurfaceFitReport* report) {
  const Eigen::MatrixX3d points = region_vertices(bone_vertices, region);
  if (points.rows() < kFewestRegionVertices) {
    throw InvalidInputError("wrap surface " + name + ": only " + std::to_string(points.rows()) +
                            " vertices of " + bone + " lie in its region (at least " +
                            std::to_string(kFewestRegionVertices) +
                            " are needed); hint: widen radius_mm or check the centre and side");
  }
  WrapObstacle obstacle;
  obstacle.name = name;
  obstacle.bone = bone;
  obstacle.shape = shape;
  Eigen::Matrix3d frame;
  double rms = 0;
  switch (shape) {
    case WrapShape::kSphere: {
      const fit::SphereFitResult sphere = fit::sphere_fit(points);
      const Eigen::Vector3d x = across(Eigen::Vector3d::UnitZ(), wrap_side);
      frame.col(0) = x;
      frame.col(2) = across(x, Eigen::Vector3d::UnitZ());
      frame.col(1) = frame.col(2).cross(x);
      obstacle.pose.translation() = sphere.center;
      obstacle.radii = Eigen::Vector3d::Constant(sphere.radius);
      rms = sphere.rms;
      break;
    }
    case WrapShape::kCylinder: {
      const fit::CylinderFitResult cylinder = fit::cylinder_fit(points, axis_hint);
      frame.col(2) = cylinder.axis;
      frame.col(0) = across(cylinder.axis, wrap_side);
      frame.col(1) = cylinder.axis.cross(frame.col(0));
      obstacle.pose.translation() = cylinder.centre;
      obstacle.radii = Eigen::Vector3d(cylinder.radius, cylinder.radius, cylinder.length);
      rms = cylinder.rms;
      break;
    }
    case WrapShape::kEllipsoid: {
      const fit::EllipsoidFitResult ellipsoid = fit::ellipsoid_fit(points);
      // x: the principal axis closest to the side (pointing along it); y, z
      // the others in cyclic order, y flipped with x to stay right-handed.
      int first = 0;
      if (wrap_side) {
        for (int k = 1; k < 3; ++k) {
          if (std::abs(ellipsoid.axes.col(k).dot(*wrap_side)) >
              std::abs(ellipsoid.axes.col(first).dot(*wrap_side))) {
            first = k;
          }
        }
      }
      const double sign = wrap_side && ellipsoid.axes.col(first).dot(*wrap_side) < 0 ? -1.0 : 1.0;
      for (int k = 0; k < 3; ++k) {
        const int from = (first + k) % 3;
        frame.col(k) = ellipsoid.axes.col(from) * (k < 2 ? sign : 1.0);
        obstacle.radii[k] = ellipsoid.semi_axes[from];
      }
      obstacle.pose.translation() = ellipsoid.centre;
      rms = ellipsoid.rms;
      break;
    }
  }
  obstacle.pose.linear() = frame;
  if (shape == WrapShape::kCylinder) {
    obstacle.radii.head<2>().array() += region.offset_mm;
  } else {
    obstacle.radii.array() += region.offset_mm;
  }
  obstacle.quadrant = wrap_side ? "+x" : "all";

  double shrink = 1.0;
  std::string shrunk_by;
  for (const NamedPoint& point : outside) {
    const double allowed = allowed_scale(obstacle, point.position, clearance_mm);
    if (allowed < shrink) {
      shrink = allowed;
      shrunk_by = point.name;
    }
  }
  if (!(shrink > 0.1)) {
    throw InvalidInputError("wrap surface " + name +
                            ": a point of its lines lies at its centre (it would have to shrink "
                            "below a tenth to leave it outside); hint: check the lines and the "
                            "region");
  }
  if (shape == WrapShape::kCylinder) {
    obstacle.radii.head<2>() *= shrink;
  } else {
    obstacle.radii *= shrink;
  }
  if (report != nullptr) {
    *report = {name, bone,   shape,     static_cast<int>(points.rows()),
               rms,  shrink, shrunk_by, obstacle.radii};
  }
  return obstacle;
}

}  // namespace mmm::atlas

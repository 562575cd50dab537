#include "core/fibres/contour_map.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Index;
using Eigen::Vector2d;
using Eigen::Vector3d;

void check_count(int count) {
  if (count < 8 || count % 8 != 0) {
    throw InvalidInputError("contour points: " + std::to_string(count) +
                            " is not a positive multiple of 8; use 32, 64 or 128");
  }
}

double cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Arc-length resampling of a closed loop from `start` (a point on segment
// start_segment -> start_segment + 1).
Contour resample_closed(const Eigen::MatrixX3d& loop, Index start_segment, const Vector3d& start,
                        int count) {
  const Index n = loop.rows();
  // The loop re-listed from the start point, closed.
  Eigen::MatrixX3d walk(n + 2, 3);
  walk.row(0) = start.transpose();
  for (Index k = 1; k <= n; ++k) {
    walk.row(k) = loop.row((start_segment + k) % n);
  }
  walk.row(n + 1) = start.transpose();
  Eigen::VectorXd along(n + 2);
  along(0) = 0.0;
  for (Index k = 1; k < walk.rows(); ++k) {
    along(k) = along(k - 1) + (walk.row(k) - walk.row(k - 1)).norm();
  }
  const double total = along(n + 1);
  Contour out(count, 3);
  Index k = 0;
  for (int j = 0; j < count; ++j) {
    const double target = total * j / count;
    while (k + 1 < walk.rows() - 1 && along(k + 1) < target) {
      ++k;
    }
    const double span = along(k + 1) - along(k);
    const double w = span > 0.0 ? (target - along(k)) / span : 0.0;
    out.row(j) = (1.0 - w) * walk.row(k) + w * walk.row(k + 1);
  }
  return out;
}

}  // namespace

Eigen::MatrixX2d square_boundary(int count) {
  check_count(count);
  Eigen::MatrixX2d points(count, 2);
  for (int j = 0; j < count; ++j) {
    // Perimeter position from (1, 0.5), counter-clockwise; sides of length 1.
    const double p = std::fmod(4.0 * j / count + 0.5, 4.0);
    if (p < 1.0) {
      points.row(j) << 1.0, p;  // right side, going up
    } else if (p < 2.0) {
      points.row(j) << 2.0 - p, 1.0;  // top, going left
    } else if (p < 3.0) {
      points.row(j) << 0.0, 3.0 - p;  // left side, going down
    } else {
      points.row(j) << p - 3.0, 0.0;  // bottom, going right
    }
  }
  return points;
}

Eigen::RowVectorXd square_mean_value_weights(const Vector2d& uv, int count) {
  const Eigen::MatrixX2d boundary = square_boundary(count);
  constexpr double kEdge = 1e-12;
  if (!uv.allFinite() || uv.minCoeff() < -kEdge || uv.maxCoeff() > 1.0 + kEdge) {
    throw InvalidInputError("square_mean_value_weights: (" + std::to_string(uv.x()) + ", " +
                            std::to_string(uv.y()) + ") is outside the unit square");
  }
  Eigen::RowVectorXd weights = Eigen::RowVectorXd::Zero(count);
  // On (or at rounding distance from) the boundary: linear along its edge.
  for (int i = 0; i < count; ++i) {
    const Vector2d a = boundary.row(i).transpose() - uv;
    const Vector2d b = boundary.row((i + 1) % count).transpose() - uv;
    const double length = (b - a).norm();
    if (std::abs(cross2(a, b)) <= kEdge * length && a.dot(b) <= 0.0) {
      const double w = a.norm() / length;
      weights(i) = 1.0 - w;
      weights((i + 1) % count) = w;
      return weights;
    }
  }
  // Inside: w_i = (tan(alpha_{i-1} / 2) + tan(alpha_i / 2)) / |p_i - x|,
  // alpha_i the angle at x from p_i to p_i+1; tan(alpha / 2) = (|a||b| -
  // a.b) / (a x b).
  Eigen::VectorXd half_tangent(count);
  for (int i = 0; i < count; ++i) {
    const Vector2d a = boundary.row(i).transpose() - uv;
    const Vector2d b = boundary.row((i + 1) % count).transpose() - uv;
    half_tangent(i) = (a.norm() * b.norm() - a.dot(b)) / cross2(a, b);
  }
  for (int i = 0; i < count; ++i) {
    const double r = (boundary.row(i).transpose() - uv).norm();
    weights(i) = (half_tangent((i + count - 1) % count) + half_tangent(i)) / r;
  }
  return weights / weights.sum();
}

Contour consistent_contour(const Eigen::MatrixX3d& loop, const Vector3d& axis,
                           const Vector3d& reference, int count) {
  check_count(count);
  const Index n = loop.rows();
  if (n < 3 || !loop.allFinite()) {
    throw InvalidInputError("consistent_contour: a loop needs at least three finite points, got " +
                            std::to_string(n));
  }
  Vector3d vector_area = Vector3d::Zero();
  Vector3d centroid = Vector3d::Zero();
  double length = 0.0;
  for (Index i = 0; i < n; ++i) {
    const Vector3d p = loop.row(i).transpose();
    const Vector3d q = loop.row((i + 1) % n).transpose();
    vector_area += p.cross(q);
    const double l = (q - p).norm();
    centroid += 0.5 * l * (p + q);
    length += l;
  }
  if (length <= 0.0 || vector_area.norm() <= 0.0) {
    throw InvalidInputError("consistent_contour: the loop has zero length or encloses no area");
  }
  centroid /= length;
  Eigen::MatrixX3d oriented = loop;
  Vector3d normal = vector_area.normalized();
  if (normal.dot(axis) < 0.0) {
    oriented = loop.colwise().reverse().eval();
    normal = -normal;
  }
  Vector3d x_axis = reference - reference.dot(normal) * normal;
  if (x_axis.norm() < 1e-9 * reference.norm() || x_axis.norm() == 0.0) {
    throw InvalidInputError(
        "consistent_contour: the reference direction is along the loop's normal; pick one across "
        "the muscle");
  }
  x_axis.normalize();
  const Vector3d y_axis = normal.cross(x_axis);
  // The outermost upward crossing of the half-line y = 0, x > 0.
  Index best_segment = -1;
  Vector3d best_point = Vector3d::Zero();
  double best_x = 0.0;
  for (Index i = 0; i < n; ++i) {
    const Vector3d p = oriented.row(i).transpose();
    const Vector3d q = oriented.row((i + 1) % n).transpose();
    const double yp = (p - centroid).dot(y_axis);
    const double yq = (q - centroid).dot(y_axis);
    if (yp < 0.0 && yq >= 0.0) {
      const double w = yp / (yp - yq);
      const Vector3d crossing = (1.0 - w) * p + w * q;
      const double x = (crossing - centroid).dot(x_axis);
      if (x > best_x) {
        best_x = x;
        best_segment = i;
        best_point = crossing;
      }
    }
  }
  if (best_segment < 0) {  // no crossing on the positive side: the farthest point along x
    Index far = 0;
    ((oriented.rowwise() - centroid.transpose()) * x_axis).maxCoeff(&far);
    best_segment = far;
    best_point = oriented.row(far).transpose();
  }
  return resample_closed(oriented, best_segment, best_point, count);
}

Contour align_start(const Contour& contour, const Contour& neighbour) {
  const Index n = contour.rows();
  if (n < 3 || neighbour.rows() != n) {
    throw InvalidInputError("align_start: contours of " + std::to_string(n) + " and " +
                            std::to_string(neighbour.rows()) +
                            " points; both need the same count, at least three");
  }
  const Eigen::MatrixX3d a = contour.rowwise() - contour.colwise().mean();
  const Eigen::MatrixX3d b = neighbour.rowwise() - neighbour.colwise().mean();
  // cost(s) = sum_i |a(i + s) - b(i)|^2 for every whole shift s.
  Eigen::VectorXd cost(n);
  for (Index s = 0; s < n; ++s) {
    double sum = 0.0;
    for (Index i = 0; i < n; ++i) {
      sum += (a.row((i + s) % n) - b.row(i)).squaredNorm();
    }
    cost(s) = sum;
  }
  Index best = 0;
  cost.minCoeff(&best);
  // The fractional part from the parabola through the best shift's neighbours.
  const double before = cost((best + n - 1) % n);
  const double after = cost((best + 1) % n);
  const double curvature = before - 2.0 * cost(best) + after;
  const double fraction =
      curvature > 0.0 ? std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5) : 0.0;
  if (best == 0 && fraction == 0.0) {
    return contour;
  }
  Contour out(n, 3);
  for (Index i = 0; i < n; ++i) {
    const double at = static_cast<double>(i + best) + fraction;
    const double whole = std::floor(at);
    const double w = at - whole;
    const Index k = ((static_cast<Index>(whole) % n) + n) % n;
    out.row(i) = (1.0 - w) * contour.row(k) + w * contour.row((k + 1) % n);
  }
  return out;
}

}  // namespace mmm::fibres

#include "core/fibres/tube.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Vector3d;

Vector3d point(const Eigen::MatrixXd& centreline, Eigen::Index i) {
  return centreline.row(i).head<3>().transpose();
}

// Unit tangents by central differences (one-sided at the ends).
std::vector<Vector3d> tangents(const Eigen::MatrixXd& centreline) {
  if (centreline.rows() < 2 || centreline.cols() < 3) {
    throw InvalidInputError("tube: a centreline needs at least two points of x y z, got " +
                            std::to_string(centreline.rows()) + " by " +
                            std::to_string(centreline.cols()));
  }
  const Eigen::Index n = centreline.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!centreline.row(i).allFinite())
      throw InvalidInputError("tube: centreline point " + std::to_string(i) + " is not finite");
    if (i > 0 && (point(centreline, i) - point(centreline, i - 1)).norm() == 0.0) {
      throw InvalidInputError("tube: centreline points " + std::to_string(i - 1) + " and " +
                              std::to_string(i) + " coincide; hint: drop repeated points");
    }
  }
  std::vector<Vector3d> result(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index before = std::max<Eigen::Index>(i - 1, 0);
    const Eigen::Index after = std::min<Eigen::Index>(i + 1, n - 1);
    Vector3d direction = point(centreline, after) - point(centreline, before);
    if (direction.norm() == 0.0)  // a hairpin: the chord ahead
      direction = point(centreline, after) - point(centreline, i);
    result[static_cast<std::size_t>(i)] = direction.normalized();
  }
  return result;
}

Frame complete(const Vector3d& tangent, const Vector3d& normal) {
  const Vector3d n = (normal - normal.dot(tangent) * tangent).normalized();
  return {tangent, n, tangent.cross(n)};
}

}  // namespace

std::vector<Frame> rotation_minimising_frames(const Eigen::MatrixXd& centreline,
                                              const Vector3d& first_normal) {
  const std::vector<Vector3d> t = tangents(centreline);
  Vector3d normal = first_normal;
  if (normal.isZero()) normal = t.front().unitOrthogonal();
  if (!normal.allFinite() ||
      (normal - normal.dot(t.front()) * t.front()).norm() < 1e-9 * std::max(1.0, normal.norm())) {
    throw InvalidInputError("tube: the first normal must be finite and not along the tangent");
  }
  std::vector<Frame> frames;
  frames.reserve(t.size());
  frames.push_back(complete(t.front(), normal));
  for (std::size_t i = 0; i + 1 < t.size(); ++i) {
    // Double reflection: in the plane bisecting the chord, then in the one
    // taking the reflected tangent onto the next tangent.
    const auto k = static_cast<Eigen::Index>(i);
    const Vector3d v1 = point(centreline, k + 1) - point(centreline, k);
    const double c1 = v1.squaredNorm();
    const Vector3d& r = frames.back().normal;
    const Vector3d r_left = r - (2.0 / c1) * v1.dot(r) * v1;
    const Vector3d t_left = t[i] - (2.0 / c1) * v1.dot(t[i]) * v1;
    const Vector3d v2 = t[i + 1] - t_left;
    const double c2 = v2.squaredNorm();
    const Vector3d r_next =
        c2 > 1e-30 ? Vector3d(r_left - (2.0 / c2) * v2.dot(r_left) * v2) : r_left;
    frames.push_back(complete(t[i + 1], r_next));
  }
  return frames;
}

std::vector<Frame> frenet_frames(const Eigen::MatrixXd& centreline) {
  const std::vector<Vector3d> t = tangents(centreline);
  const Eigen::Index n = centreline.rows();
  std::vector<Frame> frames;
  frames.reserve(t.size());
  Vector3d previous = t.front().unitOrthogonal();
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    Vector3d curvature = Vector3d::Zero();
    if (i > 0 && i + 1 < n) {
      curvature = point(centreline, i + 1) - 2.0 * point(centreline, i) + point(centreline, i - 1);
    }
    curvature -= curvature.dot(t[k]) * t[k];
    const double scale = (i + 1 < n ? point(centreline, i + 1) - point(centreline, i)
                                    : point(centreline, i) - point(centreline, i - 1))
                             .squaredNorm();
    if (curvature.norm() > 1e-12 * scale) previous = curvature;
    frames.push_back(complete(t[k], previous));
  }
  return frames;
}

mesh::IndexedMesh tube_mesh(const Eigen::MatrixXd& centreline, const Eigen::VectorXd& radii,
                            const std::vector<Frame>& frames, int sides) {
  const Eigen::Index n = centreline.rows();
  if (sides < 3) throw InvalidInputError("tube: sides must be >= 3, got " + std::to_string(sides));
  if (radii.size() != n || static_cast<Eigen::Index>(frames.size()) != n || n < 2) {
    throw InvalidInputError("tube: " + std::to_string(n) + " centreline points, " +
                            std::to_string(radii.size()) + " radii and " +
                            std::to_string(frames.size()) + " frames; they must match (>= 2)");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(radii[i] > 0.0) || !std::isfinite(radii[i])) {
      throw InvalidInputError("tube: radius " + std::to_string(i) + " must be > 0, got " +
                              std::to_string(radii[i]));
    }
  }
  mesh::IndexedMesh tube;
  tube.V.resize(n * sides + 2, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Frame& frame = frames[static_cast<std::size_t>(i)];
    for (int k = 0; k < sides; ++k) {
      const double angle = 2.0 * std::numbers::pi * k / sides;
      tube.V.row(i * sides + k) =
          (point(centreline, i) +
           radii[i] * (std::cos(angle) * frame.normal + std::sin(angle) * frame.binormal))
              .transpose();
    }
  }
  const Eigen::Index start = n * sides;
  const Eigen::Index end = start + 1;
  tube.V.row(start) = centreline.row(0).head<3>();
  tube.V.row(end) = centreline.row(n - 1).head<3>();
  tube.F.resize(2 * (n - 1) * sides + 2 * static_cast<Eigen::Index>(sides), 3);
  Eigen::Index f = 0;
  const auto at = [&](Eigen::Index i, int k) { return static_cast<int>(i * sides + (k % sides)); };
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    for (int k = 0; k < sides; ++k) {
      tube.F.row(f++) << at(i, k), at(i, k + 1), at(i + 1, k);
      tube.F.row(f++) << at(i, k + 1), at(i + 1, k + 1), at(i + 1, k);
    }
  }
  for (int k = 0; k < sides; ++k) {
    tube.F.row(f++) << static_cast<int>(start), at(0, k + 1), at(0, k);
    tube.F.row(f++) << static_cast<int>(end), at(n - 1, k), at(n - 1, k + 1);
  }
  return tube;
}

double largest_twist_step(const std::vector<Frame>& frames) {
  double largest = 0.0;
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    // Carry the normal by the smallest rotation taking one tangent to the next.
    const Eigen::Quaterniond turn =
        Eigen::Quaterniond::FromTwoVectors(frames[i].tangent, frames[i + 1].tangent);
    const Vector3d carried = turn * frames[i].normal;
    const double angle =
        std::atan2(carried.cross(frames[i + 1].normal).norm(), carried.dot(frames[i + 1].normal));
    largest = std::max(largest, angle);
  }
  return largest;
}

}  // namespace mmm::fibres

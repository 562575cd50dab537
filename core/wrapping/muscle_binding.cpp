#include "core/wrapping/muscle_binding.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <Eigen/SparseCore>

#include "core/errors.h"

namespace mmm::wrapping {
namespace {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

std::vector<double> cumulative_arc(const std::vector<Vector3d>& points) {
  std::vector<double> arc(points.size(), 0.0);
  for (std::size_t i = 1; i < points.size(); ++i)
    arc[i] = arc[i - 1] + (points[i] - points[i - 1]).norm();
  return arc;
}

// The point at arc length s (clamped to the path).
Vector3d point_at(const std::vector<Vector3d>& points, const std::vector<double>& arc, double s) {
  if (s <= 0.0) return points.front();
  if (s >= arc.back()) return points.back();
  const auto upper = std::upper_bound(arc.begin(), arc.end(), s);
  const auto i = static_cast<std::size_t>(upper - arc.begin());  // arc[i - 1] <= s < arc[i]
  const double span = arc[i] - arc[i - 1];
  const double t = span > 0 ? (s - arc[i - 1]) / span : 0.0;
  return (1.0 - t) * points[i - 1] + t * points[i];
}

Vector3d tangent_at(const std::vector<Vector3d>& points, const std::vector<double>& arc, double s,
                    double window) {
  const double half = std::min(window, 0.5 * arc.back());
  const double lo = std::clamp(s - half, 0.0, arc.back() - 2.0 * half);
  const Vector3d chord = point_at(points, arc, lo + 2.0 * half) - point_at(points, arc, lo);
  const double length = chord.norm();
  return length > 0 ? Vector3d(chord / length)
                    : Vector3d((points.back() - points.front()).normalized());
}

// Closest point of the polyline to q: (arc length there, distance).
std::pair<double, double> closest_on_path(const std::vector<Vector3d>& points,
                                          const std::vector<double>& arc, const Vector3d& q) {
  double best_distance = std::numeric_limits<double>::infinity();
  double best_arc = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Vector3d segment = points[i] - points[i - 1];
    const double length_sq = segment.squaredNorm();
    const double t =
        length_sq > 0 ? std::clamp((q - points[i - 1]).dot(segment) / length_sq, 0.0, 1.0) : 0.0;
    const double distance = (points[i - 1] + t * segment - q).norm();
    if (distance < best_distance) {
      best_distance = distance;
      best_arc = arc[i - 1] + t * (arc[i] - arc[i - 1]);
    }
  }
  return {best_arc, best_distance};
}

void check_line(const LinePath& line, std::size_t index) {
  if (line.points.size() < 2) {
    throw InvalidInputError("muscle binding: action line " + std::to_string(index) +
                            " has fewer than 2 points");
  }
  for (const Vector3d& point : line.points) {
    if (!point.allFinite()) {
      throw InvalidInputError("muscle binding: action line " + std::to_string(index) +
                              " has a non-finite point");
    }
  }
  if (cumulative_arc(line.points).back() <= 0.0) {
    throw InvalidInputError("muscle binding: action line " + std::to_string(index) +
                            " has zero length");
  }
}

// Rest arc length -> arc length now, piecewise linear between the named
// points present in both paths (and the two ends); by fraction of the
// length when either path has no names.
class ArcMap {
 public:
  ArcMap(const std::vector<std::string>& rest_names, const std::vector<double>& rest_arc,
         const std::vector<std::string>& now_names, const std::vector<double>& now_arc) {
    rest_.push_back(0.0);
    now_.push_back(0.0);
    if (rest_names.size() == rest_arc.size() && now_names.size() == now_arc.size()) {
      std::size_t from = 1;
      for (std::size_t i = 1; i + 1 < rest_names.size(); ++i) {
        if (rest_names[i].empty()) continue;
        for (std::size_t j = from; j + 1 < now_names.size(); ++j) {
          if (now_names[j] == rest_names[i] && rest_arc[i] > rest_.back() &&
              now_arc[j] > now_.back()) {
            rest_.push_back(rest_arc[i]);
            now_.push_back(now_arc[j]);
            from = j + 1;
            break;
          }
        }
      }
    }
    rest_.push_back(rest_arc.back());
    now_.push_back(now_arc.back());
  }

  [[nodiscard]] double operator()(double s) const {
    const auto upper = std::upper_bound(rest_.begin(), rest_.end(), s);
    const auto k = std::clamp<std::size_t>(static_cast<std::size_t>(upper - rest_.begin()), 1,
                                           rest_.size() - 1);
    const double span = rest_[k] - rest_[k - 1];
    const double t = span > 0 ? (s - rest_[k - 1]) / span : 0.0;
    return now_[k - 1] + t * (now_[k] - now_[k - 1]);
  }

 private:
  std::vector<double> rest_;
  std::vector<double> now_;
};

// Half the vertex, half the mean of its neighbours (rows sum to 1).
Eigen::SparseMatrix<double> neighbour_average(const Eigen::MatrixX3i& faces, Eigen::Index n) {
  std::vector<Eigen::Triplet<double>> edges;
  edges.reserve(static_cast<std::size_t>(6 * faces.rows()));
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      edges.emplace_back(faces(f, corner), faces(f, (corner + 1) % 3), 1.0);
      edges.emplace_back(faces(f, (corner + 1) % 3), faces(f, corner), 1.0);
    }
  }
  Eigen::SparseMatrix<double> adjacency(n, n);
  adjacency.setFromTriplets(edges.begin(), edges.end(), [](double, double) { return 1.0; });
  Eigen::SparseMatrix<double> averaging(n, n);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double degree = adjacency.col(i).sum();
    entries.emplace_back(i, i, degree > 0 ? 0.5 : 1.0);
    for (Eigen::SparseMatrix<double>::InnerIterator it(adjacency, i); it; ++it) {
      entries.emplace_back(i, it.row(), 0.5 / degree);
    }
  }
  averaging.setFromTriplets(entries.begin(), entries.end());
  return averaging;
}

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

Quaterniond same_hemisphere(const Quaterniond& q, const Quaterniond& reference) {
  return q.dot(reference) < 0 ? Quaterniond(-q.coeffs()) : q;
}

}  // namespace

MuscleBinding::MuscleBinding(Eigen::MatrixX3d rest_vertices, const Eigen::MatrixX3i& faces,
                             const std::vector<LinePath>& rest_lines,
                             std::vector<AttachmentBone> attachments, const BindingOptions& options)
    : rest_(std::move(rest_vertices)), attachments_(std::move(attachments)), options_(options) {
  if (!(options.attachment_band_mm > 0 && options.tangent_window_mm > 0 &&
        options.line_softening_mm > 0)) {
    throw InvalidInputError(
        "muscle binding: attachment_band_mm, tangent_window_mm and line_softening_mm must be > 0");
  }
  if (rest_lines.empty()) throw InvalidInputError("muscle binding: the muscle has no action line");
  if (!rest_.allFinite()) throw InvalidInputError("muscle binding: a rest vertex is not finite");
  const Eigen::Index n = rest_.rows();
  Eigen::VectorXd total_weight = Eigen::VectorXd::Zero(n);
  for (std::size_t l = 0; l < rest_lines.size(); ++l) {
    check_line(rest_lines[l], l);
    LineBinding binding;
    binding.rest_points = rest_lines[l].points;
    binding.rest_arc = cumulative_arc(binding.rest_points);
    if (rest_lines[l].point_names.size() == binding.rest_points.size())
      binding.rest_names = rest_lines[l].point_names;
    binding.fraction.resize(n);
    binding.weight.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto [arc, distance] =
          closest_on_path(binding.rest_points, binding.rest_arc, rest_.row(i).transpose());
      binding.fraction[i] = arc / binding.rest_arc.back();
      const double softened = distance + options.line_softening_mm;
      binding.weight[i] = 1.0 / (softened * softened);
    }
    total_weight += binding.weight;
    lines_.push_back(std::move(binding));
  }
  for (LineBinding& binding : lines_) binding.weight = binding.weight.cwiseQuotient(total_weight);
  if (options.smoothing_iterations < 0)
    throw InvalidInputError("muscle binding: smoothing_iterations must be >= 0");
  if (options.smoothing_iterations > 0 && faces.rows() > 0) {
    if (faces.minCoeff() < 0 || faces.maxCoeff() >= n) {
      throw InvalidInputError("muscle binding: a face index is outside the vertices");
    }
    const Eigen::SparseMatrix<double> averaging = neighbour_average(faces, n);
    for (LineBinding& binding : lines_) {
      for (int iteration = 0; iteration < options.smoothing_iterations; ++iteration) {
        binding.fraction = averaging * binding.fraction;
        binding.weight = averaging * binding.weight;
      }
    }
  }

  nearest_attachment_ = Eigen::VectorXi::Constant(n, -1);
  bone_blend_ = Eigen::VectorXd::Zero(n);
  for (std::size_t b = 0; b < attachments_.size(); ++b) {
    if (attachments_[b].rest_distance.size() != n) {
      throw InvalidInputError("muscle binding: attachment bone " + std::to_string(b) + " has " +
                              std::to_string(attachments_[b].rest_distance.size()) +
                              " distances for " + std::to_string(n) + " vertices");
    }
  }
  const double full = 0.25 * options.attachment_band_mm;
  for (Eigen::Index i = 0; i < n; ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t b = 0; b < attachments_.size(); ++b) {
      if (attachments_[b].rest_distance[i] < nearest) {
        nearest = attachments_[b].rest_distance[i];
        nearest_attachment_[i] = static_cast<int>(b);
      }
    }
    if (nearest >= options.attachment_band_mm) {
      nearest_attachment_[i] = -1;
      continue;
    }
    bone_blend_[i] = 1.0 - smoothstep((nearest - full) / (options.attachment_band_mm - full));
  }
}

MuscleBinding::Targets MuscleBinding::targets(const std::vector<LinePath>& lines,
                                              const std::vector<Eigen::Isometry3d>& poses) const {
  if (lines.size() != lines_.size()) {
    throw InvalidInputError("muscle binding: " + std::to_string(lines.size()) +
                            " action lines for a binding of " + std::to_string(lines_.size()));
  }
  const auto pose_count = static_cast<int>(poses.size());
  auto check_index = [&](int index) {
    if (index < 0 || index >= pose_count) {
      throw InvalidInputError("muscle binding: bone index " + std::to_string(index) +
                              " outside the " + std::to_string(pose_count) + " poses");
    }
  };
  for (std::size_t l = 0; l < lines.size(); ++l) {
    check_line(lines[l], l);
    check_index(lines[l].origin_pose_index);
    check_index(lines[l].insertion_pose_index);
  }
  for (const AttachmentBone& bone : attachments_) check_index(bone.pose_index);

  const Eigen::Index n = rest_.rows();
  Targets result;
  result.positions = Eigen::MatrixX3d::Zero(n, 3);
  result.rotations.assign(static_cast<std::size_t>(n), Matrix3d::Identity());
  std::vector<Quaterniond> rotation_sums(static_cast<std::size_t>(n), Quaterniond(0, 0, 0, 0));
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const LineBinding& binding = lines_[l];
    const std::vector<Vector3d>& now = lines[l].points;
    const std::vector<double> arc = cumulative_arc(now);
    const Quaterniond origin(
        poses[static_cast<std::size_t>(lines[l].origin_pose_index)].rotation());
    const Quaterniond insertion = same_hemisphere(
        Quaterniond(poses[static_cast<std::size_t>(lines[l].insertion_pose_index)].rotation()),
        origin);
    const ArcMap arc_map(binding.rest_names, binding.rest_arc, lines[l].point_names, arc);
    // Per path point: its bone's rotation, all in one hemisphere.
    std::vector<Quaterniond> point_rotations;
    if (lines[l].point_pose_indices.size() == now.size()) {
      for (const int index : lines[l].point_pose_indices) {
        check_index(index);
        point_rotations.push_back(
            same_hemisphere(Quaterniond(poses[static_cast<std::size_t>(index)].rotation()),
                            point_rotations.empty() ? origin : point_rotations.back()));
      }
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      const double a = binding.fraction[i];
      const double s0 = a * binding.rest_arc.back();
      const double st = arc_map(s0);
      const Vector3d c0 = point_at(binding.rest_points, binding.rest_arc, s0);
      const Vector3d ct = point_at(now, arc, st);
      Quaterniond bones;
      if (point_rotations.empty()) {
        bones = origin.slerp(a, insertion);
      } else {
        const auto upper = std::upper_bound(arc.begin(), arc.end(), st);
        const auto k = std::clamp<std::size_t>(static_cast<std::size_t>(upper - arc.begin()), 1,
                                               arc.size() - 1);
        const double span = arc[k] - arc[k - 1];
        const double t = span > 0 ? std::clamp((st - arc[k - 1]) / span, 0.0, 1.0) : 0.0;
        bones = point_rotations[k - 1].slerp(t, point_rotations[k]);
      }
      const Vector3d turned =
          bones * tangent_at(binding.rest_points, binding.rest_arc, s0, options_.tangent_window_mm);
      const Vector3d tangent = tangent_at(now, arc, st, options_.tangent_window_mm);
      const Quaterniond rotation = Quaterniond::FromTwoVectors(turned, tangent) * bones;
      const double w = binding.weight[i];
      result.positions.row(i) += w * (ct + rotation * (rest_.row(i).transpose() - c0)).transpose();
      Quaterniond& sum = rotation_sums[static_cast<std::size_t>(i)];
      const Quaterniond aligned = l == 0 ? rotation : same_hemisphere(rotation, sum);
      sum.coeffs() += w * aligned.coeffs();
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    Quaterniond line_rotation = rotation_sums[static_cast<std::size_t>(i)].normalized();
    const int bone = nearest_attachment_[i];
    if (bone >= 0) {
      const Eigen::Isometry3d& pose =
          poses[static_cast<std::size_t>(attachments_[static_cast<std::size_t>(bone)].pose_index)];
      const double beta = bone_blend_[i];
      const Vector3d rigid = pose * Vector3d(rest_.row(i).transpose());
      result.positions.row(i) = (1.0 - beta) * result.positions.row(i) + beta * rigid.transpose();
      line_rotation = line_rotation.slerp(beta, Quaterniond(pose.rotation()));
    }
    result.rotations[static_cast<std::size_t>(i)] = line_rotation.toRotationMatrix();
  }
  return result;
}

}  // namespace mmm::wrapping

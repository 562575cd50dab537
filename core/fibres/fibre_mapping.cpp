#include "core/fibres/fibre_mapping.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "core/errors.h"
#include "core/fibres/contour_map.h"
#include "core/fibres/contour_stack.h"
#include "core/fibres/keep_inside.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/winding_number.h"

namespace mmm::fibres {

using Eigen::Index;
using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<Fibre> fibres_through_contours(const std::vector<Contour>& contours,
                                           const std::vector<TemplateFibre>& templates) {
  if (contours.size() < 2) {
    throw InvalidInputError("fibres_through_contours: at least two contours are needed");
  }
  const Index points = contours.front().rows();
  for (const Contour& contour : contours) {
    if (contour.rows() != points) {
      throw InvalidInputError("fibres_through_contours: contours of different point counts");
    }
  }
  const auto levels = static_cast<Index>(contours.size());
  std::vector<Fibre> fibres;
  fibres.reserve(templates.size());
  for (const TemplateFibre& fibre : templates) {
    Fibre mapped(levels, 3);
    for (Index k = 0; k < levels; ++k) {
      const double s = static_cast<double>(k) / static_cast<double>(levels - 1);
      const Vector2d uv = fibre.at(s).cwiseMax(0.0).cwiseMin(1.0);
      const Eigen::RowVectorXd weights = square_mean_value_weights(uv, static_cast<int>(points));
      mapped.row(k) = weights * contours[static_cast<std::size_t>(k)];
    }
    fibres.push_back(std::move(mapped));
  }
  return fibres;
}

namespace {

// Each coordinate replaced by its rank among the points' (ties in order of
// index) over count - 1: [0, 1], evenly spread whatever the clustering.
Eigen::MatrixX2d quantile_layout(const Eigen::MatrixX2d& plane) {
  const Index n = plane.rows();
  Eigen::MatrixX2d out = Eigen::MatrixX2d::Constant(n, 2, 0.5);
  if (n < 2) {
    return out;
  }
  std::vector<Index> order(static_cast<std::size_t>(n));
  for (int c = 0; c < 2; ++c) {
    std::iota(order.begin(), order.end(), Index{0});
    std::stable_sort(order.begin(), order.end(),
                     [&](Index a, Index b) { return plane(a, c) < plane(b, c); });
    for (Index r = 0; r < n; ++r) {
      out(order[static_cast<std::size_t>(r)], c) =
          static_cast<double>(r) / static_cast<double>(n - 1);
    }
  }
  return out;
}

}  // namespace

std::vector<int> match_ends(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& ends,
                            const MuscleAxes& axes, EndLayout layout) {
  if (points.rows() == 0) {
    throw InvalidInputError("match_ends: the attachment area has no points");
  }
  std::vector<int> chosen(static_cast<std::size_t>(ends.rows()), 0);
  if (ends.rows() == 0) {
    return chosen;
  }
  const Eigen::RowVector3d centre = points.colwise().mean();
  const Eigen::MatrixX3d centred = points.rowwise() - centre;
  Eigen::Matrix<double, 3, 2> plane;
  if (layout == EndLayout::kCrossSection) {
    plane.col(0) = axes.reference;
    plane.col(1) = axes.axis.cross(axes.reference);
  } else {  // the area's two directions of largest spread
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(centred.transpose() * centred);
    plane = solver.eigenvectors().rightCols<2>();
  }
  const Eigen::MatrixX2d area = quantile_layout(centred * plane);
  const Eigen::MatrixX2d wanted = quantile_layout((ends.rowwise() - centre) * plane);
  for (Index i = 0; i < wanted.rows(); ++i) {
    Index best = 0;
    (area.rowwise() - wanted.row(i)).rowwise().squaredNorm().minCoeff(&best);
    chosen[static_cast<std::size_t>(i)] = static_cast<int>(best);
  }
  return chosen;
}

namespace {

// Points of the quadratic Bezier target -> control -> end, excluding `end`,
// about `spacing` apart.
std::vector<Vector3d> bridge(const Vector3d& target, const Vector3d& end,
                             const Vector3d& direction_into_target, double spacing) {
  const double gap = (target - end).norm();
  if (gap < 1e-9) {
    return {};
  }
  const Vector3d control = end + 0.5 * gap * direction_into_target;
  const int steps = std::max(1, static_cast<int>(std::ceil(gap / std::max(spacing, 1e-9))));
  std::vector<Vector3d> out;
  for (int i = 0; i < steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    const double r = 1.0 - t;
    out.emplace_back(r * r * target + 2.0 * r * t * control + t * t * end);
  }
  return out;
}

}  // namespace

Fibre extend_fibre(const Fibre& fibre, const Vector3d& origin_target,
                   const Vector3d& insertion_target) {
  const Index n = fibre.rows();
  if (n < 2) {
    throw InvalidInputError("extend_fibre: a fibre needs at least two points");
  }
  const double spacing = fibre_length(fibre) / static_cast<double>(n - 1);
  const Vector3d first = fibre.row(0).transpose();
  const Vector3d last = fibre.row(n - 1).transpose();
  Vector3d back = first - fibre.row(1).transpose();  // direction out of the origin end
  Vector3d ahead = last - fibre.row(n - 2).transpose();
  back = back.norm() > 0.0 ? back.normalized() : Vector3d::Zero();
  ahead = ahead.norm() > 0.0 ? ahead.normalized() : Vector3d::Zero();
  const std::vector<Vector3d> head = bridge(origin_target, first, back, spacing);
  std::vector<Vector3d> tail = bridge(insertion_target, last, ahead, spacing);
  std::reverse(tail.begin(), tail.end());
  Fibre out(static_cast<Index>(head.size() + tail.size()) + n, 3);
  Index row = 0;
  for (const Vector3d& p : head) {
    out.row(row++) = p.transpose();
  }
  out.middleRows(row, n) = fibre;
  row += n;
  for (const Vector3d& p : tail) {
    out.row(row++) = p.transpose();
  }
  return out;
}

ContourFibres contour_sections(const mesh::IndexedMesh& surface, const Eigen::VectorXd& values,
                               const std::vector<double>& levels, const MuscleAxes& axes,
                               int contour_points) {
  ContourStack stack = contour_stack(surface, values, levels, axes.reference, contour_points);
  ContourFibres result;
  result.contours = std::move(stack.contours);
  result.interpolated_contours = stack.interpolated;
  result.axes = axes;
  return result;
}

namespace {

// Fibre f extended to the surface points nearest attachment points
// origin_of[f] and insertion_of[f], smoothed, resampled to `segments` and
// kept inside `surface`; returns the points moved inside.
int extend_to_attachments(std::vector<Fibre>& fibres, const mesh::IndexedMesh& surface,
                          const Attachments& attachments, const std::vector<int>& origin_of,
                          const std::vector<int>& insertion_of, int segments,
                          int smoothing_passes) {
  const mesh::AabbTree tree(surface);
  const mesh::WindingNumber inside(tree);
  for (std::size_t f = 0; f < fibres.size(); ++f) {
    const Vector3d origin_target =
        tree.closest_point(attachments.origin.row(origin_of[f]).transpose()).point;
    const Vector3d insertion_target =
        tree.closest_point(attachments.insertion.row(insertion_of[f]).transpose()).point;
    Fibre whole = extend_fibre(fibres[f], origin_target, insertion_target);
    smooth_fibre(whole, smoothing_passes);
    fibres[f] = resample_fibre(whole, segments);
  }
  return keep_inside(fibres, inside, kInsideMarginMm);
}

}  // namespace

void finish_fibres(ContourFibres& result, const mesh::IndexedMesh& surface,
                   const std::vector<Fibre>& mapped, const Attachments& attachments,
                   const DecompositionOptions& options, EndLayout layout) {
  Eigen::MatrixX3d starts(static_cast<Index>(mapped.size()), 3);
  Eigen::MatrixX3d ends(static_cast<Index>(mapped.size()), 3);
  for (std::size_t f = 0; f < mapped.size(); ++f) {
    starts.row(static_cast<Index>(f)) = mapped[f].row(0);
    ends.row(static_cast<Index>(f)) = mapped[f].row(mapped[f].rows() - 1);
  }
  result.fibres = mapped;
  result.moved_inside =
      extend_to_attachments(result.fibres, surface, attachments,
                            match_ends(attachments.origin, starts, result.axes, layout),
                            match_ends(attachments.insertion, ends, result.axes, layout),
                            options.segments, options.smoothing_passes);
}

void finish_template_fibres(ContourFibres& result, const mesh::IndexedMesh& surface,
                            const Attachments& attachments, const DecompositionOptions& options,
                            EndLayout layout) {
  const std::vector<TemplateFibre> templates =
      fibre_template(options.architecture, options.fibres, attachments.narrow_at_insertion());
  finish_fibres(result, surface, fibres_through_contours(result.contours, templates), attachments,
                options, layout);
}

int connect_to_nearest_attachments(std::vector<Fibre>& fibres, const mesh::IndexedMesh& surface,
                                   const Attachments& attachments, int segments,
                                   int smoothing_passes) {
  const auto nearest = [](const Eigen::MatrixX3d& points, const Eigen::RowVector3d& end) {
    Index best = 0;
    (points.rowwise() - end).rowwise().squaredNorm().minCoeff(&best);
    return static_cast<int>(best);
  };
  std::vector<int> origin_of;
  std::vector<int> insertion_of;
  for (const Fibre& fibre : fibres) {
    if (fibre.rows() < 2) {
      throw InvalidInputError("connect_to_nearest_attachments: a fibre has fewer than two points");
    }
    origin_of.push_back(nearest(attachments.origin, fibre.row(0)));
    insertion_of.push_back(nearest(attachments.insertion, fibre.row(fibre.rows() - 1)));
  }
  return extend_to_attachments(fibres, surface, attachments, origin_of, insertion_of, segments,
                               smoothing_passes);
}

void smooth_fibre(Fibre& fibre, int passes) {
  const Index n = fibre.rows();
  for (int pass = 0; pass < passes && n > 2; ++pass) {
    const Fibre before = fibre;
    for (Index i = 1; i + 1 < n; ++i) {
      fibre.row(i) = 0.5 * before.row(i) + 0.25 * (before.row(i - 1) + before.row(i + 1));
    }
  }
}

double fibre_length(const Fibre& fibre) {
  double length = 0.0;
  for (Index i = 1; i < fibre.rows(); ++i) {
    length += (fibre.row(i) - fibre.row(i - 1)).norm();
  }
  return length;
}

Fibre resample_fibre(const Fibre& fibre, int segments) {
  const Index n = fibre.rows();
  if (n < 2 || segments < 1) {
    throw InvalidInputError("resample_fibre: needs >= 2 points and >= 1 segment");
  }
  Eigen::VectorXd along(n);
  along(0) = 0.0;
  for (Index i = 1; i < n; ++i) {
    along(i) = along(i - 1) + (fibre.row(i) - fibre.row(i - 1)).norm();
  }
  Fibre out(segments + 1, 3);
  Index k = 0;
  for (int j = 0; j <= segments; ++j) {
    const double target = along(n - 1) * j / segments;
    while (k + 2 < n && along(k + 1) < target) {
      ++k;
    }
    const double span = along(k + 1) - along(k);
    const double w = span > 0.0 ? std::clamp((target - along(k)) / span, 0.0, 1.0) : 0.0;
    out.row(j) = (1.0 - w) * fibre.row(k) + w * fibre.row(k + 1);
  }
  return out;
}

}  // namespace mmm::fibres

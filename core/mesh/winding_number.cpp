#include "core/mesh/winding_number.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numbers>
#include <string>

#include "core/errors.h"

namespace mmm::mesh {
namespace {

// The traversal pushes both children of a visited node: at most one pending
// entry per level plus one, and the tree depth is at most 31 (median split).
constexpr int kStackSize = 64;

// q counts as lying in a triangle's plane when the triple product is below
// this fraction of |a||b||c|: rounding (~1e-16 relative) decides its sign there.
constexpr double kCoplanar = 1e-13;

// Signed solid angle of triangle (a, b, c) seen from q (Van Oosterom &
// Strackee 1983): tan(omega / 2) = a.(b x c) / (|a||b||c| + (a.b)|c| +
// (b.c)|a| + (c.a)|b|) with a, b, c relative to q. Positive when q is on the
// side the counter-clockwise normal points away from (the inside). In the
// plane of the triangle the answer is 0 (the mean of the limits +-2 pi from
// either side when q is inside the triangle), so that w = 1/2 on a closed
// surface rather than 0 or 1 at the whim of rounding.
double solid_angle(const Eigen::Vector3d& a_world, const Eigen::Vector3d& b_world,
                   const Eigen::Vector3d& c_world, const Eigen::Vector3d& q) {
  const Eigen::Vector3d a = a_world - q;
  const Eigen::Vector3d b = b_world - q;
  const Eigen::Vector3d c = c_world - q;
  const double la = a.norm();
  const double lb = b.norm();
  const double lc = c.norm();
  const double numerator = a.dot(b.cross(c));
  if (std::abs(numerator) <= kCoplanar * la * lb * lc) return 0.0;
  const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  return 2.0 * std::atan2(numerator, denominator);
}

}  // namespace

WindingNumber::WindingNumber(const AabbTree& tree) : WindingNumber(tree, Options{}) {}

WindingNumber::WindingNumber(const AabbTree& tree, const Options& options)
    : tree_(&tree), options_(options) {
  if (!(options.beta > 1.0) || !std::isfinite(options.beta)) {
    throw InvalidInputError("WindingNumber: beta must be a finite number > 1, got " +
                            std::to_string(options.beta) +
                            " (the default 2 is accurate to about 1e-3)");
  }
  const IndexedMesh& mesh = tree.mesh();
  const std::vector<int>& order = tree.face_order();
  const size_t num_faces = order.size();
  corners_.resize(num_faces);
  std::vector<double> areas(num_faces);
  std::vector<Eigen::Vector3d> vector_areas(num_faces);
  std::vector<Eigen::Vector3d> centroids(num_faces);
  // Second moment of each face about its own centroid: for a flat triangle
  // the integral of (x - c)(x - c)^T dA / area = sum over corners of
  // (v - c)(v - c)^T / 12.
  std::vector<Eigen::Matrix3d> covariances(num_faces);
  for (size_t i = 0; i < num_faces; ++i) {
    const int f = order[i];
    Corners& corners = corners_[i];
    corners.a = mesh.V.row(mesh.F(f, 0)).transpose();
    corners.b = mesh.V.row(mesh.F(f, 1)).transpose();
    corners.c = mesh.V.row(mesh.F(f, 2)).transpose();
    vector_areas[i] = 0.5 * (corners.b - corners.a).cross(corners.c - corners.a);
    areas[i] = vector_areas[i].norm();
    centroids[i] = (corners.a + corners.b + corners.c) / 3.0;
    covariances[i].setZero();
    for (const Eigen::Vector3d* corner : {&corners.a, &corners.b, &corners.c}) {
      const Eigen::Vector3d offset = *corner - centroids[i];
      covariances[i] += offset * offset.transpose() / 12.0;
    }
  }

  // Children follow their parent in nodes(), so a reverse sweep sees both
  // children of a node before the node itself. A child's moments move to the
  // parent's centre p by x - p = (x - p_child) + delta, delta = p_child - p:
  //   M   += M_c + N_c delta^T
  //   T_i += T_c,i + m_i delta^T + delta m_i^T + N_c,i delta delta^T
  // (m_i = row i of M_c). A face is a child with p_c = its centroid, M_c = 0
  // and T_c,i = N_i * covariance.
  const std::vector<AabbTree::Node>& nodes = tree.nodes();
  moments_.resize(nodes.size());
  std::vector<double> node_area(nodes.size(), 0.0);
  for (size_t n = nodes.size(); n-- > 0;) {
    const AabbTree::Node& node = nodes[n];
    NodeMoments& moments = moments_[n];
    moments.vector_area.setZero();
    Eigen::Vector3d weighted_centroid = Eigen::Vector3d::Zero();
    if (node.is_leaf()) {
      for (int i = node.begin; i < node.end; ++i) {
        const auto k = static_cast<size_t>(i);
        moments.vector_area += vector_areas[k];
        node_area[n] += areas[k];
        weighted_centroid += areas[k] * centroids[k];
      }
    } else {
      for (const size_t child : {n + 1, static_cast<size_t>(node.second_child)}) {
        moments.vector_area += moments_[child].vector_area;
        node_area[n] += node_area[child];
        weighted_centroid += node_area[child] * moments_[child].centre;
      }
    }
    // Zero-area faces only: every moment is zero, any centre in the box works.
    moments.centre = node_area[n] > 0 ? Eigen::Vector3d(weighted_centroid / node_area[n])
                                      : Eigen::Vector3d(node.box.center());

    moments.first.setZero();
    for (Eigen::Matrix3d& t : moments.second) t.setZero();
    const auto add_child = [&moments](const Eigen::Vector3d& child_area,
                                      const Eigen::Vector3d& child_centre,
                                      const Eigen::Matrix3d& child_first,
                                      const std::array<Eigen::Matrix3d, 3>& child_second) {
      const Eigen::Vector3d delta = child_centre - moments.centre;
      moments.first += child_first + child_area * delta.transpose();
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d m = child_first.row(i).transpose();
        moments.second[static_cast<size_t>(i)] +=
            child_second[static_cast<size_t>(i)] + m * delta.transpose() +
            delta * m.transpose() + child_area[i] * delta * delta.transpose();
      }
    };
    if (node.is_leaf()) {
      for (int i = node.begin; i < node.end; ++i) {
        const auto k = static_cast<size_t>(i);
        std::array<Eigen::Matrix3d, 3> face_second;
        for (int j = 0; j < 3; ++j) {
          face_second[static_cast<size_t>(j)] = vector_areas[k][j] * covariances[k];
        }
        add_child(vector_areas[k], centroids[k], Eigen::Matrix3d::Zero(), face_second);
      }
    } else {
      for (const size_t child : {n + 1, static_cast<size_t>(node.second_child)}) {
        add_child(moments_[child].vector_area, moments_[child].centre, moments_[child].first,
                  moments_[child].second);
      }
    }
    for (int i = 0; i < 3; ++i) {
      moments.second_traces[i] = moments.second[static_cast<size_t>(i)].trace();
    }

    double radius_squared = 0;
    for (int i = node.begin; i < node.end; ++i) {
      const Corners& corners = corners_[static_cast<size_t>(i)];
      for (const Eigen::Vector3d* corner : {&corners.a, &corners.b, &corners.c}) {
        radius_squared = std::max(radius_squared, (*corner - moments.centre).squaredNorm());
      }
    }
    moments.far_squared = options.beta * options.beta * radius_squared;
  }
}

double WindingNumber::at(const Eigen::Vector3d& q) const {
  if (!q.allFinite()) throw InvalidInputError("WindingNumber::at: the query point is not finite");
  const std::vector<AabbTree::Node>& nodes = tree_->nodes();
  std::array<int, kStackSize> stack{};
  int top = 0;
  stack[static_cast<size_t>(top++)] = 0;
  double total = 0;
  while (top > 0) {
    const int n = stack[static_cast<size_t>(--top)];
    const NodeMoments& moments = moments_[static_cast<size_t>(n)];
    const Eigen::Vector3d d = moments.centre - q;
    const double d2 = d.squaredNorm();
    if (d2 > moments.far_squared) {
      const double inverse_d2 = 1.0 / d2;
      const double inverse_d3 = inverse_d2 / std::sqrt(d2);
      const double inverse_d5 = inverse_d3 * inverse_d2;
      double contracted = 0;  // sum_i (T_i d)_i
      double cubic = 0;       // sum_i d_i d.T_i d
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d t_d = moments.second[static_cast<size_t>(i)] * d;
        contracted += t_d[i];
        cubic += d[i] * d.dot(t_d);
      }
      total += moments.vector_area.dot(d) * inverse_d3 +
               (moments.first.trace() * inverse_d3 - 3.0 * d.dot(moments.first * d) * inverse_d5) +
               (-1.5 * (2.0 * contracted + d.dot(moments.second_traces)) * inverse_d5 +
                7.5 * cubic * inverse_d5 * inverse_d2);
      continue;
    }
    const AabbTree::Node& node = nodes[static_cast<size_t>(n)];
    if (node.is_leaf()) {
      for (int i = node.begin; i < node.end; ++i) {
        const Corners& corners = corners_[static_cast<size_t>(i)];
        total += solid_angle(corners.a, corners.b, corners.c, q);
      }
      continue;
    }
    assert(top + 2 <= kStackSize);
    stack[static_cast<size_t>(top++)] = node.second_child;
    stack[static_cast<size_t>(top++)] = n + 1;
  }
  return total / (4.0 * std::numbers::pi);
}

double winding_number_exact(const IndexedMesh& mesh, const Eigen::Vector3d& q) {
  validate_indices_and_coordinates(mesh);
  if (!q.allFinite()) {
    throw InvalidInputError("winding_number_exact: the query point is not finite");
  }
  double total = 0;
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    total += solid_angle(mesh.V.row(mesh.F(f, 0)).transpose(), mesh.V.row(mesh.F(f, 1)).transpose(),
                         mesh.V.row(mesh.F(f, 2)).transpose(), q);
  }
  return total / (4.0 * std::numbers::pi);
}

}  // namespace mmm::mesh

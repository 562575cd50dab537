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
constexpr int kBallTraversalStackSize = 64;

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
                            " (the default 2 keeps the error below 1e-2)");
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
  struct Moments {
    Eigen::Vector3d vector_area = Eigen::Vector3d::Zero();
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double area = 0;
    Eigen::Matrix3d first = Eigen::Matrix3d::Zero();
    std::array<Eigen::Matrix3d, 3> second{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero(),
                                          Eigen::Matrix3d::Zero()};
  };
  const std::vector<AabbTree::Node>& nodes = tree.nodes();
  std::vector<Moments> moments(nodes.size());
  const auto add_child = [](Moments& parent, const Eigen::Vector3d& child_area,
                            const Eigen::Vector3d& child_centre, const Eigen::Matrix3d& child_first,
                            const std::array<Eigen::Matrix3d, 3>& child_second) {
    const Eigen::Vector3d delta = child_centre - parent.centre;
    parent.first += child_first + child_area * delta.transpose();
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d m = child_first.row(i).transpose();
      parent.second[static_cast<size_t>(i)] += child_second[static_cast<size_t>(i)] +
                                               m * delta.transpose() + delta * m.transpose() +
                                               child_area[i] * delta * delta.transpose();
    }
  };
  balls_.resize(nodes.size());
  expansions_.resize(nodes.size());
  for (size_t n = nodes.size(); n-- > 0;) {
    const AabbTree::Node& node = nodes[n];
    Moments& here = moments[n];
    Eigen::Vector3d weighted_centroid = Eigen::Vector3d::Zero();
    if (node.is_leaf()) {
      for (int i = node.begin; i < node.end; ++i) {
        const auto k = static_cast<size_t>(i);
        here.vector_area += vector_areas[k];
        here.area += areas[k];
        weighted_centroid += areas[k] * centroids[k];
      }
    } else {
      for (const size_t child : {n + 1, static_cast<size_t>(node.second_child)}) {
        here.vector_area += moments[child].vector_area;
        here.area += moments[child].area;
        weighted_centroid += moments[child].area * moments[child].centre;
      }
    }
    // Zero-area faces only: every moment is zero, any centre in the box works.
    here.centre = here.area > 0 ? Eigen::Vector3d(weighted_centroid / here.area)
                                : Eigen::Vector3d(node.box.center());
    if (node.is_leaf()) {
      for (int i = node.begin; i < node.end; ++i) {
        const auto k = static_cast<size_t>(i);
        std::array<Eigen::Matrix3d, 3> face_second;
        for (int j = 0; j < 3; ++j) {
          face_second[static_cast<size_t>(j)] = vector_areas[k][j] * covariances[k];
        }
        add_child(here, vector_areas[k], centroids[k], Eigen::Matrix3d::Zero(), face_second);
      }
    } else {
      for (const size_t child : {n + 1, static_cast<size_t>(node.second_child)}) {
        add_child(here, moments[child].vector_area, moments[child].centre, moments[child].first,
                  moments[child].second);
      }
    }

    double radius_squared = 0;
    for (int i = node.begin; i < node.end; ++i) {
      const Corners& corners = corners_[static_cast<size_t>(i)];
      for (const Eigen::Vector3d* corner : {&corners.a, &corners.b, &corners.c}) {
        radius_squared = std::max(radius_squared, (*corner - here.centre).squaredNorm());
      }
    }
    NodeBall& ball = balls_[n];
    ball.centre = here.centre;
    ball.far_squared = options.beta * options.beta * radius_squared;
    ball.second_child = node.second_child;
    ball.begin = node.begin;
    ball.end = node.end;
    NodeExpansion& expansion = expansions_[n];
    expansion.vector_area = here.vector_area;
    for (size_t r = 0; r < 3; ++r) {
      for (size_t c = 0; c < 3; ++c) {
        expansion.first[3 * r + c] =
            here.first(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
      }
      const Eigen::Matrix3d& t = here.second[r];
      expansion.second[r] = {t(0, 0), t(1, 1), t(2, 2), t(0, 1), t(0, 2), t(1, 2)};
    }
  }
}

double WindingNumber::at(const Eigen::Vector3d& q) const {
  if (!q.allFinite()) throw InvalidInputError("WindingNumber::at: the query point is not finite");
  std::array<int, kBallTraversalStackSize> stack{};
  int top = 0;
  stack[static_cast<size_t>(top++)] = 0;
  double total = 0;
  while (top > 0) {
    const int n = stack[static_cast<size_t>(--top)];
    const NodeBall& ball = balls_[static_cast<size_t>(n)];
    const Eigen::Vector3d d = ball.centre - q;
    const double d2 = d.squaredNorm();
    if (d2 > ball.far_squared) {
      total += far_field(expansions_[static_cast<size_t>(n)], d, d2);
      continue;
    }
    if (ball.second_child < 0) {
      for (int i = ball.begin; i < ball.end; ++i) {
        const Corners& corners = corners_[static_cast<size_t>(i)];
        total += solid_angle(corners.a, corners.b, corners.c, q);
      }
      continue;
    }
    assert(top + 2 <= kBallTraversalStackSize);
    stack[static_cast<size_t>(top++)] = ball.second_child;
    stack[static_cast<size_t>(top++)] = n + 1;
  }
  return total / (4.0 * std::numbers::pi);
}

double WindingNumber::far_field(const NodeExpansion& e, const Eigen::Vector3d& d, double d2) {
  const double inverse_d2 = 1.0 / d2;
  const double inverse_d3 = inverse_d2 / std::sqrt(d2);
  const double inverse_d5 = inverse_d3 * inverse_d2;
  const std::array<double, 9>& m = e.first;
  const double dipole = e.vector_area.dot(d);
  const double m_trace = m[0] + m[4] + m[8];
  const double m_form = d.x() * (m[0] * d.x() + m[1] * d.y() + m[2] * d.z()) +
                        d.y() * (m[3] * d.x() + m[4] * d.y() + m[5] * d.z()) +
                        d.z() * (m[6] * d.x() + m[7] * d.y() + m[8] * d.z());
  double contracted = 0;  // sum_i (T_i d)_i
  double traced = 0;      // d . (tr T_0, tr T_1, tr T_2)
  double cubic = 0;       // sum_i d_i d.T_i d
  for (size_t i = 0; i < 3; ++i) {
    const std::array<double, 6>& t = e.second[i];  // xx yy zz xy xz yz
    const Eigen::Vector3d t_d(t[0] * d.x() + t[3] * d.y() + t[4] * d.z(),
                              t[3] * d.x() + t[1] * d.y() + t[5] * d.z(),
                              t[4] * d.x() + t[5] * d.y() + t[2] * d.z());
    const double d_i = d[static_cast<Eigen::Index>(i)];
    contracted += t_d[static_cast<Eigen::Index>(i)];
    traced += d_i * (t[0] + t[1] + t[2]);
    cubic += d_i * d.dot(t_d);
  }
  return (dipole + m_trace) * inverse_d3 - 3.0 * m_form * inverse_d5 -
         1.5 * (2.0 * contracted + traced) * inverse_d5 + 7.5 * cubic * inverse_d5 * inverse_d2;
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

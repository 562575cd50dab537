#include "core/mesh/aabb_tree.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <string>
#include <utility>

#include "core/errors.h"

namespace mmm::mesh {
namespace {

// Traversal stacks hold at most one pending entry per level (closest point,
// first hit) or two (all hits); the median split bounds the depth by
// ceil(log2 #F) <= 31 for any int-indexed mesh.
constexpr int kTraversalStackSize = 64;

// A hit this far outside a triangle (barycentric units) still counts, so that a
// ray through a shared edge is caught by at least one of the two faces.
constexpr double kBarycentricSlack = 1e-10;

// A ray is parallel to a triangle when |cos(angle to the normal)| * sin(corner
// angle) falls below this: the determinant of Moller-Trumbore is then noise.
constexpr double kParallelTolerance = 1e-12;

// Hits this close (relative to the bounding-box diagonal) on faces sharing a
// vertex are one crossing of the surface.
constexpr double kSameHitTolerance = 1e-9;

// Boxes are inflated by this fraction of the diagonal for ray tests, so that the
// slack above and the rounding of the slab test cannot lose a hit.
constexpr double kBoxPad = 1e-9;

// Nearest floats below / above x (bounds of boxes stored in floats).
float round_down(double x) {
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  if (x > kFloatMax) return std::numeric_limits<float>::max();
  if (x < -kFloatMax) return -std::numeric_limits<float>::infinity();
  auto f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

float round_up(double x) { return -round_down(-x); }

struct BuildState {
  const IndexedMesh* mesh = nullptr;
  const std::vector<Eigen::Vector3d>* centroids = nullptr;
  std::vector<int>* order = nullptr;
  std::vector<AabbTree::Node>* nodes = nullptr;
  int max_leaf_size = 4;
  int max_depth = 0;
};

Eigen::AlignedBox3d face_range_box(const BuildState& state, int begin, int end) {
  Eigen::AlignedBox3d box;
  const IndexedMesh& mesh = *state.mesh;
  for (int i = begin; i < end; ++i) {
    const int f = (*state.order)[static_cast<size_t>(i)];
    for (int k = 0; k < 3; ++k) box.extend(mesh.V.row(mesh.F(f, k)).transpose());
  }
  return box;
}

// Builds the subtree over order[begin, end) and returns its node index.
int build_node(BuildState& state, int begin, int end, int depth) {
  const int index = static_cast<int>(state.nodes->size());
  state.nodes->emplace_back();
  state.max_depth = std::max(state.max_depth, depth);
  {
    AabbTree::Node& node = state.nodes->back();
    node.box = face_range_box(state, begin, end);
    node.begin = begin;
    node.end = end;
  }
  if (end - begin <= state.max_leaf_size) return index;

  Eigen::AlignedBox3d centroid_box;
  for (int i = begin; i < end; ++i) {
    centroid_box.extend(
        (*state.centroids)[static_cast<size_t>((*state.order)[static_cast<size_t>(i)])]);
  }
  Eigen::Index axis = 0;
  centroid_box.sizes().maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  auto* const first = state.order->data();
  const auto& centroids = *state.centroids;
  std::nth_element(first + begin, first + middle, first + end, [&](int lhs, int rhs) {
    return centroids[static_cast<size_t>(lhs)][axis] < centroids[static_cast<size_t>(rhs)][axis];
  });
  build_node(state, begin, middle, depth + 1);
  const int second = build_node(state, middle, end, depth + 1);
  // The vector may have grown: index again rather than keeping a reference.
  (*state.nodes)[static_cast<size_t>(index)].second_child = second;
  return index;
}

double box_squared_distance(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& q) {
  // Branch-free: the gap along an axis is max(0, lo - q, q - hi).
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    const double gap = std::max(0.0, std::max(box.min()[k] - q[k], q[k] - box.max()[k]));
    sum += gap * gap;
  }
  return sum;
}

// Closest point of segment p0 + s * edge, s in [0, 1], to q: returns s.
double segment_parameter(const Eigen::Vector3d& p0, const Eigen::Vector3d& edge,
                         const Eigen::Vector3d& q) {
  const double length2 = edge.squaredNorm();
  if (length2 <= 0) return 0;
  return std::clamp(edge.dot(q - p0) / length2, 0.0, 1.0);
}

// Closest point of triangle (a, a + ab, a + ac) to p by Voronoi regions of
// the vertices, edges and face (Ericson 2005, 5.1.5). Writes the weights
// (of b, of c) of the answer and returns its squared distance to p.
double closest_on_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& ab,
                           const Eigen::Vector3d& ac, const Eigen::Vector3d& p, double& v,
                           double& w) {
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) {  // vertex a
    v = 0;
    w = 0;
    return ap.squaredNorm();
  }
  const Eigen::Vector3d bp = ap - ab;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) {  // vertex b
    v = 1;
    w = 0;
    return bp.squaredNorm();
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {  // edge ab
    const double denominator = d1 - d3;
    v = denominator > 0 ? d1 / denominator : 0;
    w = 0;
    return (ap - v * ab).squaredNorm();
  }
  const Eigen::Vector3d cp = ap - ac;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) {  // vertex c
    v = 0;
    w = 1;
    return cp.squaredNorm();
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {  // edge ac
    const double denominator = d2 - d6;
    v = 0;
    w = denominator > 0 ? d2 / denominator : 0;
    return (ap - w * ac).squaredNorm();
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {  // edge bc
    const double denominator = (d4 - d3) + (d5 - d6);
    w = denominator > 0 ? (d4 - d3) / denominator : 0;
    v = 1 - w;
    return (bp - w * (ac - ab)).squaredNorm();
  }
  const double sum = va + vb + vc;
  if (sum > 0 && std::isfinite(sum)) {  // interior of the face
    v = vb / sum;
    w = vc / sum;
    return (ap - v * ab - w * ac).squaredNorm();
  }
  // Degenerate (zero-area) triangle that rounding sent past every region test:
  // the answer lies on one of its edges.
  const double s_ab = segment_parameter(a, ab, p);
  const double s_ac = segment_parameter(a, ac, p);
  const Eigen::Vector3d bc = ac - ab;
  const double s_bc = segment_parameter(a + ab, bc, p);
  const double d_ab = (ap - s_ab * ab).squaredNorm();
  const double d_ac = (ap - s_ac * ac).squaredNorm();
  const double d_bc = (bp - s_bc * bc).squaredNorm();
  if (d_ab <= d_ac && d_ab <= d_bc) {
    v = s_ab;
    w = 0;
    return d_ab;
  }
  if (d_ac <= d_bc) {
    v = 0;
    w = s_ac;
    return d_ac;
  }
  v = 1 - s_bc;
  w = s_bc;
  return d_bc;
}

// Per-ray constants of the slab test.
struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;
  Eigen::Vector3d inverse;         // 1 / direction where finite
  std::array<bool, 3> parallel{};  // direction component 0 (or subnormal)
  double direction_squared_norm = 0;
};

Ray make_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  Ray ray;
  ray.origin = origin;
  ray.direction = direction;
  ray.direction_squared_norm = direction.squaredNorm();
  for (int k = 0; k < 3; ++k) {
    const double inverse = 1.0 / direction[k];
    ray.parallel[static_cast<size_t>(k)] = !std::isfinite(inverse);
    ray.inverse[k] = ray.parallel[static_cast<size_t>(k)] ? 0.0 : inverse;
  }
  return ray;
}

// Entry parameter of the ray into the box (inflated by pad) within [0, t_max],
// or nullopt when it misses. Axes the ray is parallel to are tested by the
// origin's coordinate, never by 0 * infinity.
std::optional<double> ray_box_entry(const Ray& ray, const Eigen::AlignedBox3d& box, double pad,
                                    double t_max) {
  double t_enter = 0;
  double t_exit = t_max;
  for (int k = 0; k < 3; ++k) {
    const double lo = box.min()[k] - pad;
    const double hi = box.max()[k] + pad;
    if (ray.parallel[static_cast<size_t>(k)]) {
      if (ray.origin[k] < lo || ray.origin[k] > hi) return std::nullopt;
      continue;
    }
    double t0 = (lo - ray.origin[k]) * ray.inverse[k];
    double t1 = (hi - ray.origin[k]) * ray.inverse[k];
    if (t0 > t1) std::swap(t0, t1);
    t_enter = std::max(t_enter, t0);
    t_exit = std::min(t_exit, t1);
    if (t_enter > t_exit) return std::nullopt;
  }
  return t_enter;
}

// Moller & Trumbore 1997. Writes t and the weights (u of b, v of c) on a hit.
bool ray_triangle(const Ray& ray, const Eigen::Vector3d& a, const Eigen::Vector3d& ab,
                  const Eigen::Vector3d& ac, double t_max, double& t, double& u, double& v) {
  const Eigen::Vector3d p = ray.direction.cross(ac);
  const double det = ab.dot(p);
  const double scale2 = ray.direction_squared_norm * ab.squaredNorm() * ac.squaredNorm();
  if (det * det <= kParallelTolerance * kParallelTolerance * scale2) return false;
  const double inverse_det = 1.0 / det;
  const Eigen::Vector3d s = ray.origin - a;
  u = s.dot(p) * inverse_det;
  if (u < -kBarycentricSlack || u > 1 + kBarycentricSlack) return false;
  const Eigen::Vector3d q = s.cross(ab);
  v = ray.direction.dot(q) * inverse_det;
  if (v < -kBarycentricSlack || u + v > 1 + kBarycentricSlack) return false;
  t = ac.dot(q) * inverse_det;
  if (!(t >= 0 && t <= t_max)) return false;
  // Report weights of a point of the triangle even for hits in the slack.
  u = std::max(u, 0.0);
  v = std::max(v, 0.0);
  if (u + v > 1) {
    const double sum = u + v;
    u /= sum;
    v /= sum;
  }
  return true;
}

}  // namespace

AabbTree::AabbTree(IndexedMesh mesh) : AabbTree(std::move(mesh), Options{}) {}

AabbTree::AabbTree(IndexedMesh mesh, const Options& options) : mesh_(std::move(mesh)) {
  if (options.max_leaf_size < 1) {
    throw InvalidInputError("AabbTree: max_leaf_size must be at least 1, got " +
                            std::to_string(options.max_leaf_size));
  }
  if (mesh_.empty()) {
    throw InvalidInputError("AabbTree: the mesh has no face (" +
                            std::to_string(mesh_.num_vertices()) +
                            " vertices, 0 faces); a spatial query needs a surface");
  }
  validate_indices_and_coordinates(mesh_);
  build(options);
}

void AabbTree::build(const Options& options) {
  const auto num_faces = static_cast<size_t>(mesh_.num_faces());
  std::vector<Eigen::Vector3d> centroids(num_faces);
  for (size_t f = 0; f < num_faces; ++f) {
    const auto row = static_cast<Eigen::Index>(f);
    centroids[f] =
        (mesh_.V.row(mesh_.F(row, 0)) + mesh_.V.row(mesh_.F(row, 1)) + mesh_.V.row(mesh_.F(row, 2)))
            .transpose() /
        3.0;
  }
  face_order_.resize(num_faces);
  for (size_t f = 0; f < num_faces; ++f) face_order_[f] = static_cast<int>(f);
  nodes_.clear();
  nodes_.reserve(2 * num_faces / static_cast<size_t>(options.max_leaf_size) + 2);

  BuildState state;
  state.mesh = &mesh_;
  state.centroids = &centroids;
  state.order = &face_order_;
  state.nodes = &nodes_;
  state.max_leaf_size = options.max_leaf_size;
  build_node(state, 0, static_cast<int>(num_faces), 0);
  depth_ = state.max_depth;
  assert(depth_ < kTraversalStackSize - 1);

  build_compact();
  box_pad_ = kBoxPad * std::max(bounds().diagonal().norm(), std::numeric_limits<double>::min());
}

void AabbTree::build_compact() {
  // Vertices renumbered in order of first use by the faces in leaf order, so
  // that the faces of a leaf (and of neighbouring leaves) share cache lines.
  const auto num_faces = face_order_.size();
  std::vector<int> renumbered(static_cast<size_t>(mesh_.num_vertices()), -1);
  points_.clear();
  corners_.resize(num_faces);
  for (size_t i = 0; i < num_faces; ++i) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh_.F(face_order_[i], k);
      int& slot = renumbered[static_cast<size_t>(v)];
      if (slot < 0) {
        slot = static_cast<int>(points_.size());
        points_.emplace_back(mesh_.V.row(v).transpose());
      }
      corners_[i][static_cast<size_t>(k)] = slot;
    }
  }

  std::vector<int> code(nodes_.size(), 0);  // pair index, or ~leaf index
  int num_pairs = 0;
  leaf_start_.clear();
  for (size_t n = 0; n < nodes_.size(); ++n) {
    if (nodes_[n].is_leaf()) {
      code[n] = ~static_cast<int>(leaf_start_.size());
      leaf_start_.push_back(nodes_[n].begin);
    } else {
      code[n] = num_pairs++;
    }
  }
  // Leaves in depth-first order tile [0, #F): each starts where the last ended.
  leaf_start_.push_back(static_cast<int>(num_faces));

  pairs_.resize(static_cast<size_t>(num_pairs));
  for (size_t n = 0; n < nodes_.size(); ++n) {
    if (nodes_[n].is_leaf()) continue;
    ChildPair& pair = pairs_[static_cast<size_t>(code[n])];
    const std::array<size_t, 2> children = {n + 1, static_cast<size_t>(nodes_[n].second_child)};
    for (size_t j = 0; j < 2; ++j) {
      const Eigen::AlignedBox3d& box = nodes_[children[j]].box;
      const auto lane = static_cast<Eigen::Index>(j);
      for (size_t k = 0; k < 3; ++k) {
        pair.lo[k][lane] = round_down(box.min()[static_cast<Eigen::Index>(k)]);
        pair.hi[k][lane] = round_up(box.max()[static_cast<Eigen::Index>(k)]);
      }
      pair.child[j] = code[children[j]];
    }
  }
}

AabbTree::ClosestPoint AabbTree::search_closest(const Eigen::Vector3d& query, double bound) const {
  struct Entry {
    int code;  // pair index, or ~leaf index
    double squared_distance;
  };
  std::array<Entry, kTraversalStackSize> stack{};
  int top = 0;
  double best = bound;
  int best_position = -1;
  double best_v = 0;
  double best_w = 0;

  int code = pairs_.empty() ? ~0 : 0;
  bool active = box_squared_distance(nodes_.front().box, query) < best;
  while (active) {
    if (code < 0) {
      const int leaf_index = ~code;
      const auto leaf = static_cast<size_t>(leaf_index);
      for (int i = leaf_start_[leaf]; i < leaf_start_[leaf + 1]; ++i) {
        const std::array<int, 3>& corners = corners_[static_cast<size_t>(i)];
        const Eigen::Vector3d& a = points_[static_cast<size_t>(corners[0])];
        const Eigen::Vector3d ab = points_[static_cast<size_t>(corners[1])] - a;
        const Eigen::Vector3d ac = points_[static_cast<size_t>(corners[2])] - a;
        double v = 0;
        double w = 0;
        const double d2 = closest_on_triangle(a, ab, ac, query, v, w);
        if (d2 < best) {
          best = d2;
          best_position = i;
          best_v = v;
          best_w = w;
        }
      }
      active = false;
    } else {
      const ChildPair& pair = pairs_[static_cast<size_t>(code)];
      // Both children at once (SIMD lanes): per axis the gap to a box is
      // max(0, lo - q, q - hi), branch free. The float bounds are exact in
      // double and enclose the true boxes, so this stays a lower bound.
      Eigen::Array2d sum = Eigen::Array2d::Zero();
      for (size_t k = 0; k < 3; ++k) {
        const double q = query[static_cast<Eigen::Index>(k)];
        const Eigen::Array2d gap =
            (pair.lo[k].cast<double>() - q).max(q - pair.hi[k].cast<double>()).max(0.0);
        sum += gap * gap;
      }
      const Eigen::Index near = sum[1] < sum[0] ? 1 : 0;
      const Eigen::Index far = 1 - near;
      if (sum[far] < best) {
        stack[static_cast<size_t>(top++)] = {pair.child[static_cast<size_t>(far)], sum[far]};
      }
      active = sum[near] < best;
      code = pair.child[static_cast<size_t>(near)];
    }
    while (!active && top > 0) {
      const Entry& entry = stack[static_cast<size_t>(--top)];
      if (entry.squared_distance < best) {
        code = entry.code;
        active = true;
      }
    }
  }

  ClosestPoint result;
  if (best_position < 0) return result;
  const std::array<int, 3>& corners = corners_[static_cast<size_t>(best_position)];
  const Eigen::Vector3d& a = points_[static_cast<size_t>(corners[0])];
  result.point = a + best_v * (points_[static_cast<size_t>(corners[1])] - a) +
                 best_w * (points_[static_cast<size_t>(corners[2])] - a);
  result.face = face_order_[static_cast<size_t>(best_position)];
  result.squared_distance = best;
  result.barycentric = Eigen::Vector3d(1 - best_v - best_w, best_v, best_w);
  return result;
}

AabbTree::ClosestPoint AabbTree::closest_point(const Eigen::Vector3d& query) const {
  if (!query.allFinite()) {
    throw InvalidInputError("AabbTree::closest_point: the query point is not finite");
  }
  return search_closest(query, std::numeric_limits<double>::infinity());
}

std::optional<AabbTree::ClosestPoint> AabbTree::closest_point_within(
    const Eigen::Vector3d& query, double max_squared_distance) const {
  if (!query.allFinite()) {
    throw InvalidInputError("AabbTree::closest_point_within: the query point is not finite");
  }
  if (std::isnan(max_squared_distance)) {
    throw InvalidInputError("AabbTree::closest_point_within: max_squared_distance is NaN");
  }
  if (max_squared_distance < 0) return std::nullopt;
  // Strict comparisons inside the search: nudge the bound so that a face at
  // exactly the given distance is still found.
  ClosestPoint result = search_closest(
      query, std::nextafter(max_squared_distance, std::numeric_limits<double>::infinity()));
  if (result.face < 0) return std::nullopt;
  return result;
}

void AabbTree::check_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                         double t_max) const {
  if (!origin.allFinite() || !direction.allFinite()) {
    throw InvalidInputError("AabbTree ray query: origin and direction must be finite");
  }
  if (direction.squaredNorm() == 0) {
    throw InvalidInputError("AabbTree ray query: the direction is the zero vector");
  }
  if (std::isnan(t_max)) throw InvalidInputError("AabbTree ray query: t_max is NaN");
}

std::optional<AabbTree::RayHit> AabbTree::first_hit(const Eigen::Vector3d& origin,
                                                    const Eigen::Vector3d& direction,
                                                    double t_max) const {
  check_ray(origin, direction, t_max);
  if (t_max < 0) return std::nullopt;
  const Ray ray = make_ray(origin, direction);
  struct Entry {
    int node;
    double t_enter;
  };
  std::array<Entry, kTraversalStackSize> stack{};
  int top = 0;
  double best_t = t_max;
  int best_position = -1;
  double best_u = 0;
  double best_v = 0;

  int node = ray_box_entry(ray, nodes_.front().box, box_pad_, best_t) ? 0 : -1;
  while (node >= 0) {
    const Node& current = nodes_[static_cast<size_t>(node)];
    if (current.is_leaf()) {
      for (int i = current.begin; i < current.end; ++i) {
        const std::array<int, 3>& corners = corners_[static_cast<size_t>(i)];
        const Eigen::Vector3d& a = points_[static_cast<size_t>(corners[0])];
        double t = 0;
        double u = 0;
        double v = 0;
        if (ray_triangle(ray, a, points_[static_cast<size_t>(corners[1])] - a,
                         points_[static_cast<size_t>(corners[2])] - a, best_t, t, u, v) &&
            (best_position < 0 || t < best_t)) {
          best_t = t;
          best_position = i;
          best_u = u;
          best_v = v;
        }
      }
      node = -1;
    } else {
      int near = node + 1;
      int far = current.second_child;
      std::optional<double> near_t =
          ray_box_entry(ray, nodes_[static_cast<size_t>(near)].box, box_pad_, best_t);
      std::optional<double> far_t =
          ray_box_entry(ray, nodes_[static_cast<size_t>(far)].box, box_pad_, best_t);
      if (far_t && (!near_t || *far_t < *near_t)) {
        std::swap(near, far);
        std::swap(near_t, far_t);
      }
      if (far_t) stack[static_cast<size_t>(top++)] = {far, *far_t};
      node = near_t ? near : -1;
    }
    while (node < 0 && top > 0) {
      const Entry& entry = stack[static_cast<size_t>(--top)];
      if (entry.t_enter <= best_t) node = entry.node;
    }
  }
  if (best_position < 0) return std::nullopt;
  RayHit hit;
  hit.t = best_t;
  hit.face = face_order_[static_cast<size_t>(best_position)];
  hit.barycentric = Eigen::Vector3d(1 - best_u - best_v, best_u, best_v);
  return hit;
}

bool AabbTree::share_vertex(int face_a, int face_b) const {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (mesh_.F(face_a, i) == mesh_.F(face_b, j)) return true;
    }
  }
  return false;
}

std::vector<AabbTree::RayHit> AabbTree::all_hits(const Eigen::Vector3d& origin,
                                                 const Eigen::Vector3d& direction,
                                                 double t_max) const {
  check_ray(origin, direction, t_max);
  std::vector<RayHit> hits;
  if (t_max < 0) return hits;
  const Ray ray = make_ray(origin, direction);
  std::array<int, kTraversalStackSize> stack{};
  int top = 0;
  if (ray_box_entry(ray, nodes_.front().box, box_pad_, t_max))
    stack[static_cast<size_t>(top++)] = 0;
  while (top > 0) {
    const Node& current = nodes_[static_cast<size_t>(stack[static_cast<size_t>(--top)])];
    if (current.is_leaf()) {
      for (int i = current.begin; i < current.end; ++i) {
        const std::array<int, 3>& corners = corners_[static_cast<size_t>(i)];
        const Eigen::Vector3d& a = points_[static_cast<size_t>(corners[0])];
        double t = 0;
        double u = 0;
        double v = 0;
        if (ray_triangle(ray, a, points_[static_cast<size_t>(corners[1])] - a,
                         points_[static_cast<size_t>(corners[2])] - a, t_max, t, u, v)) {
          hits.push_back(
              {t, face_order_[static_cast<size_t>(i)], Eigen::Vector3d(1 - u - v, u, v)});
        }
      }
      continue;
    }
    const int first_child = static_cast<int>(&current - nodes_.data()) + 1;
    for (const int child : {current.second_child, first_child}) {
      if (ray_box_entry(ray, nodes_[static_cast<size_t>(child)].box, box_pad_, t_max)) {
        stack[static_cast<size_t>(top++)] = child;
      }
    }
  }
  std::sort(hits.begin(), hits.end(), [](const RayHit& lhs, const RayHit& rhs) {
    return lhs.t < rhs.t || (lhs.t == rhs.t && lhs.face < rhs.face);
  });

  // Merge the faces around a shared edge or vertex crossed by the ray. Within a
  // run of hits at the same point, a hit is dropped when it shares a vertex
  // with a hit already kept in that run.
  const double same_t =
      kSameHitTolerance * bounds().diagonal().norm() / std::sqrt(ray.direction_squared_norm);
  std::vector<RayHit> merged;
  merged.reserve(hits.size());
  size_t run_start = 0;
  for (const RayHit& hit : hits) {
    if (!merged.empty() && hit.t - merged[run_start].t > same_t) run_start = merged.size();
    bool duplicate = false;
    for (size_t k = run_start; k < merged.size() && !duplicate; ++k) {
      duplicate = share_vertex(merged[k].face, hit.face);
    }
    if (!duplicate) merged.push_back(hit);
  }
  return merged;
}

}  // namespace mmm::mesh

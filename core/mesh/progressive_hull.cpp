// Progressive outer hull (Sander, Gu, Gortler, Hoppe & Snyder 2000,
// "Silhouette clipping", section 3: progressive hulls).
//
//   for every edge (v0, v1): cost = added volume of its best outward collapse
//   while #F > target and the heap is not empty:
//     pop the cheapest edge; skip it when stale (its neighbourhood changed)
//     collapse v0 -> v1, move v1 to the edge's position x*
//     re-cost the edges of v1 and of its neighbours
//
// Position of an edge collapse. Let R be the faces around v0 or v1 (the two
// one-rings; the two faces on the edge are removed, every other face of R
// keeps its two far corners b, c and gets the new vertex x). Outward means x
// lies on or outside the plane of every face of R:
//   n_f . x >= n_f . p_f      (n_f outward unit normal, p_f a corner of f)
// and then the new fan encloses the old one. The volume change is linear in x:
// with the divergence theorem about any point o,
//   dV(x) = sum_{f in R \ edge faces} (x - o) . ((b - o) x (c - o)) / 6
//           - sum_{f in R} det(a - o, b - o, c - o) / 6,
// whose gradient c = sum (b - o) x (c - o) / 6 is a third of the area vector
// of the link polygon, independent of x. The old fan spans the same polygon,
// so c is also a third of the sum of the old faces' area vectors: a
// non-negative combination of the constraint normals, and the LP is bounded
// whenever it is feasible. So x* solves a 3-variable LP:
//   minimise dV(x) subject to the |R| half-spaces.
// It is solved exactly as the strictly convex
//   minimise c . x + (eps / 2) |x - m|^2,   eps = 1e-6 of the LP's scale,
// whose minimiser is the LP's optimal vertex when there is one and otherwise
// (flat or cylindrical neighbourhoods, where a whole plane or line of
// positions add the same volume) the optimal point nearest the edge midpoint
// m. At most three planes are active at the minimiser, and any active set
// whose solution is feasible with non-negative multipliers (KKT) gives it:
//   1. each single plane (flat neighbourhoods; O(|R|))
//   2. the dual simplex method from a triple whose normals hold c in their
//      cone: a few pivots to the optimal vertex, or a proof of infeasibility
//      (curved neighbourhoods, all but ~1e-4 of the calls on the VHF muscles)
//   3. otherwise every pair (creases), then every triple (O(|R|^3))
// A minimiser far from the edge would be a spike and is refused like an
// infeasible LP.
//
// The chosen x is then pushed outward by the (rounding-sized) amount it
// violates any half-space by, so that each collapse keeps the previous
// surface inside in floating point and containment cannot creep.

#include "core/mesh/progressive_hull.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <queue>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/signed_distance.h"

namespace mmm::mesh {
namespace {

using Vec3 = Eigen::Vector3d;

// Feasibility and multiplier tolerance, relative to the neighbourhood's
// radius and to the objective's scale.
constexpr double kRelativeTolerance = 1e-9;
// Weight of the tie-breaking distance term, relative to the objective.
constexpr double kTieBreak = 1e-6;
// Active sets whose normals are this close to dependent (Gram determinant or
// triple product of unit normals) give no unique point and are skipped.
constexpr double kSingular = 1e-10;
// A collapse whose new vertex lands farther from the edge midpoint than this
// many neighbourhood radii is refused: it would grow a spike. (Never binding
// on the VHF muscles: optima lie within the neighbourhood.)
constexpr double kFarFactor = 3.0;
// A new face whose height is below this fraction of its longest edge is
// degenerate: its normal, the next collapses' constraint, would be noise.
constexpr double kDegenerateHeight = 1e-6;
// A merged vertex may get at most this many neighbours. Flat sides add no
// volume whatever collapses, so without a limit they fan out from a few
// vertices of valence ~100, and the placement LP grows with the valence.
// Curved surfaces stay far below it (17 at most on the VHF muscles).
constexpr size_t kMaxValence = 20;
// The outward nudge follows the neighbourhood's mean normal; it is refused
// when some face is nearly perpendicular to it (cosine below this).
constexpr double kMinNudgeCosine = 0.05;

// Half-space n . x >= d, in coordinates relative to the edge midpoint.
struct Plane {
  Vec3 n;
  double d;
};

// A face of the neighbourhood that survives the collapse: its far corners
// (relative to the midpoint, counter-clockwise after the collapsing vertex)
// and its unit normal before the collapse.
struct KeptFace {
  Vec3 b;
  Vec3 c;
  Vec3 normal;
};

// Three planes taken as active: their intersection and, through Cramer's
// rule, the coefficients of any vector in the basis of their normals.
struct Basis {
  std::array<size_t, 3> index{};
  std::array<Vec3, 3> cross;  // n_j x n_l, n_l x n_i, n_i x n_j
  double det = 0;             // n_i . (n_j x n_l)

  Basis(const std::vector<Plane>& planes, size_t i, size_t j, size_t l) : index{i, j, l} {
    cross[0] = planes[j].n.cross(planes[l].n);
    cross[1] = planes[l].n.cross(planes[i].n);
    cross[2] = planes[i].n.cross(planes[j].n);
    det = planes[i].n.dot(cross[0]);
  }
  [[nodiscard]] bool singular() const { return std::abs(det) < kSingular; }
  // The point on all three planes.
  [[nodiscard]] Vec3 vertex(const std::vector<Plane>& planes) const {
    return (planes[index[0]].d * cross[0] + planes[index[1]].d * cross[1] +
            planes[index[2]].d * cross[2]) /
           det;
  }
  // Coefficient m of v in the basis of the three normals.
  [[nodiscard]] double coefficient(const Vec3& v, size_t m) const { return v.dot(cross[m]) / det; }
};

// Minimiser of c . x + (eps / 2) |x|^2 subject to the planes (see the file
// header), or nothing when the problem is infeasible or the minimiser lies
// beyond kFarFactor radii (a spike). Coordinates are relative to the edge
// midpoint; `scale` is the neighbourhood's radius.
class PlacementSolver {
 public:
  enum class Outcome { kOptimal, kInfeasible, kUndecided };

  std::optional<Vec3> solve(const std::vector<Plane>& planes, const Vec3& c, double scale) {
    planes_ = &planes;
    c_ = c;
    eps_ = kTieBreak * std::max(c.norm(), 1e-3 * scale * scale) / scale;
    tolerance_ = kRelativeTolerance * scale;
    multiplier_tolerance_ = kRelativeTolerance * (c.norm() + eps_ * scale);
    far_squared_ = (kFarFactor * scale) * (kFarFactor * scale);
    if (auto x = single_plane()) return x;
    Vec3 x = Vec3::Zero();
    switch (dual_simplex(x)) {
      case Outcome::kOptimal:
        return x;
      case Outcome::kInfeasible:
        return std::nullopt;
      case Outcome::kUndecided:
        break;
    }
    if (auto pair = all_pairs()) return pair;
    return all_triples();
  }

 private:
  [[nodiscard]] bool feasible(const Vec3& x) const {
    if (!x.allFinite() || x.squaredNorm() > far_squared_) return false;
    return std::all_of(planes_->begin(), planes_->end(),
                       [&](const Plane& p) { return p.n.dot(x) >= p.d - tolerance_; });
  }

  // KKT for three active planes: multipliers of c + eps x are non-negative
  // and x is feasible.
  [[nodiscard]] bool optimal(const Basis& basis, const Vec3& x) const {
    const Vec3 g = c_ + eps_ * x;
    for (size_t m = 0; m < 3; ++m) {
      if (basis.coefficient(g, m) < -multiplier_tolerance_) return false;
    }
    return feasible(x);
  }

  // One active plane: x = (lambda n - c) / eps on the plane. The answer in
  // flat neighbourhoods, where every triple of normals is singular. x is
  // formed as d n minus the in-plane part of c over eps, re-projected: c's
  // rounding divided by eps must not move x off the plane.
  [[nodiscard]] std::optional<Vec3> single_plane() const {
    for (const Plane& p : *planes_) {
      const double lambda = p.n.dot(c_) + eps_ * p.d;
      if (lambda < -multiplier_tolerance_) continue;
      Vec3 tangential = c_ - p.n.dot(c_) * p.n;
      tangential -= p.n.dot(tangential) * p.n;
      const Vec3 x = p.d * p.n - tangential / eps_;
      if (feasible(x)) return x;
    }
    return std::nullopt;
  }

  // The LP's optimal vertex by the dual simplex method: start from three
  // planes whose normals have c in their cone (dual feasible), then swap the
  // most violated plane in for the basis plane the ratio test picks, until
  // the vertex is feasible. A few pivots instead of all triples. An unbounded
  // dual (no basis plane can leave) proves the half-spaces have no common
  // point. Undecided when no start is found among the triples holding the
  // normal closest to c (normals of rank < 3: flat sides, creases), on a
  // singular basis, after too many pivots, or when the vertex is not the
  // tie-broken optimum (a degenerate LP): the exhaustive search decides.
  [[nodiscard]] Outcome dual_simplex(Vec3& optimum) const {
    const std::vector<Plane>& planes = *planes_;
    const size_t k = planes.size();
    size_t first = 0;
    for (size_t i = 1; i < k; ++i) {
      if (planes[i].n.dot(c_) > planes[first].n.dot(c_)) first = i;
    }
    std::optional<Basis> basis;
    for (size_t j = 0; j < k && !basis; ++j) {
      for (size_t l = j + 1; l < k && j != first; ++l) {
        if (l == first) continue;
        const Basis candidate(planes, first, j, l);
        if (candidate.singular()) continue;
        if (candidate.coefficient(c_, 0) >= 0.0 && candidate.coefficient(c_, 1) >= 0.0 &&
            candidate.coefficient(c_, 2) >= 0.0) {
          basis = candidate;
          break;
        }
      }
    }
    if (!basis) return Outcome::kUndecided;
    for (size_t pivot = 0; pivot < 4 * k; ++pivot) {
      const Vec3 x = basis->vertex(planes);
      size_t entering = k;
      double worst = tolerance_;
      for (size_t p = 0; p < k; ++p) {
        const double violation = planes[p].d - planes[p].n.dot(x);
        if (violation > worst) {
          worst = violation;
          entering = p;
        }
      }
      if (entering == k) {
        if (!optimal(*basis, x)) return Outcome::kUndecided;
        optimum = x;
        return Outcome::kOptimal;
      }
      // Ratio test: lambda_B - t w stays >= 0, with n_entering = sum w_m n_m.
      size_t leaving = 3;
      double ratio = std::numeric_limits<double>::infinity();
      for (size_t m = 0; m < 3; ++m) {
        const double w = basis->coefficient(planes[entering].n, m);
        if (w <= kSingular) continue;
        const double t = std::max(0.0, basis->coefficient(c_, m)) / w;
        if (t < ratio) {
          ratio = t;
          leaving = m;
        }
      }
      if (leaving == 3) return Outcome::kInfeasible;
      std::array<size_t, 3> index = basis->index;
      index[leaving] = entering;
      basis.emplace(planes, index[0], index[1], index[2]);
      if (basis->singular()) return Outcome::kUndecided;
    }
    return Outcome::kUndecided;
  }

  // Every triple of planes, filtered by the signs of c's coefficients (the
  // eps x part of the multipliers is at most eps * far * |n_a x n_b| / |det|).
  [[nodiscard]] std::optional<Vec3> all_triples() const {
    const std::vector<Plane>& planes = *planes_;
    const size_t k = planes.size();
    const double far = std::sqrt(far_squared_);
    for (size_t i = 0; i < k; ++i) {
      for (size_t j = i + 1; j < k; ++j) {
        for (size_t l = j + 1; l < k; ++l) {
          const Basis basis(planes, i, j, l);
          if (basis.singular()) continue;
          bool possible = true;
          for (size_t m = 0; m < 3 && possible; ++m) {
            const double slack = eps_ * far * basis.cross[m].norm() / std::abs(basis.det);
            possible = basis.coefficient(c_, m) >= -multiplier_tolerance_ - slack;
          }
          if (!possible) continue;
          const Vec3 x = basis.vertex(planes);
          if (optimal(basis, x)) return x;
        }
      }
    }
    return std::nullopt;
  }

  // Two active planes: Gram system for the multipliers, then x as the line's
  // point nearest the midpoint minus c's part along the line over eps. The
  // answer along creases of flat sides (two distinct normals only).
  [[nodiscard]] std::optional<Vec3> all_pairs() const {
    const std::vector<Plane>& planes = *planes_;
    const size_t k = planes.size();
    for (size_t i = 0; i < k; ++i) {
      for (size_t j = i + 1; j < k; ++j) {
        const double g = planes[i].n.dot(planes[j].n);
        const double det = 1.0 - g * g;
        if (det < kSingular) continue;
        const double r_i = planes[i].n.dot(c_) + eps_ * planes[i].d;
        const double r_j = planes[j].n.dot(c_) + eps_ * planes[j].d;
        const double lambda_i = (r_i - g * r_j) / det;
        const double lambda_j = (r_j - g * r_i) / det;
        if (lambda_i < -multiplier_tolerance_ || lambda_j < -multiplier_tolerance_) continue;
        const Vec3 on_line = ((planes[i].d - g * planes[j].d) * planes[i].n +
                              (planes[j].d - g * planes[i].d) * planes[j].n) /
                             det;
        const Vec3 direction = planes[i].n.cross(planes[j].n) / std::sqrt(det);
        const Vec3 x = on_line - (direction.dot(c_) / eps_) * direction;
        if (feasible(x)) return x;
      }
    }
    return std::nullopt;
  }

  const std::vector<Plane>* planes_ = nullptr;
  Vec3 c_ = Vec3::Zero();
  double eps_ = 0;
  double tolerance_ = 0;
  double multiplier_tolerance_ = 0;
  double far_squared_ = 0;
};

struct Placement {
  double added_volume = 0;       // mm^3
  Vec3 position = Vec3::Zero();  // merged vertex (mm, absolute)
};

class CollapseEvaluator {
 public:
  CollapseEvaluator(Mesh& mesh, double max_normal_deviation_degrees)
      : mesh_(mesh),
        min_cosine_(std::cos(max_normal_deviation_degrees * std::numbers::pi / 180.0)) {}

  // The best outward placement for collapsing edge e, or nothing when no
  // position is outward without folding a face. The topological test
  // (link condition) is left to the caller: it only matters for the few
  // edges that reach the top of the queue.
  std::optional<Placement> evaluate(Mesh::EdgeHandle e) {
    const Mesh::HalfedgeHandle h = mesh_.halfedge_handle(e, 0);
    const Mesh::VertexHandle v0 = mesh_.from_vertex_handle(h);
    const Mesh::VertexHandle v1 = mesh_.to_vertex_handle(h);
    const Vec3 midpoint = 0.5 * (to_eigen(mesh_.point(v0)) + to_eigen(mesh_.point(v1)));
    if (!gather(v0, v1, midpoint)) return std::nullopt;

    std::optional<Vec3> x = solver_.solve(planes_, gradient_, radius_);
    if (!x || !push_outward(*x) || !faces_stay_valid(*x)) return std::nullopt;
    return Placement{gradient_.dot(*x) - old_volume_, midpoint + *x};
  }

 private:
  // Fills planes_, kept_, gradient_, old_volume_ and radius_ for the
  // neighbourhood of edge (v0, v1); false when a face has no normal or the
  // merged vertex would exceed kMaxValence.
  bool gather(Mesh::VertexHandle v0, Mesh::VertexHandle v1, const Vec3& midpoint) {
    planes_.clear();
    kept_.clear();
    gradient_.setZero();
    old_volume_ = 0.0;
    double radius_squared = 0.0;
    for (const auto& [center, other] : {std::pair{v0, v1}, std::pair{v1, v0}}) {
      for (const auto out : mesh_.voh_range(center)) {
        const Mesh::VertexHandle vb = mesh_.to_vertex_handle(out);
        const Mesh::VertexHandle vc = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(out));
        const bool on_edge = vb == other || vc == other;
        if (on_edge && center == v1) continue;  // already met from v0
        const Vec3 a = to_eigen(mesh_.point(center)) - midpoint;
        const Vec3 b = to_eigen(mesh_.point(vb)) - midpoint;
        const Vec3 c = to_eigen(mesh_.point(vc)) - midpoint;
        const Vec3 area_vector = (b - a).cross(c - a);
        const double norm = area_vector.norm();
        if (!(norm > 0.0)) return false;
        const Vec3 normal = area_vector / norm;
        planes_.push_back({normal, normal.dot(a)});
        old_volume_ += a.dot(b.cross(c)) / 6.0;
        if (!on_edge) {
          gradient_ += b.cross(c) / 6.0;
          kept_.push_back({b, c, normal});
        }
        radius_squared =
            std::max({radius_squared, a.squaredNorm(), b.squaredNorm(), c.squaredNorm()});
      }
    }
    radius_ = std::sqrt(radius_squared);
    // The merged vertex's valence is #R - 2 on a closed mesh.
    return radius_ > 0.0 && planes_.size() <= kMaxValence + 2;
  }

  // Moves x out of every half-space it violates in floating point (by the
  // solver's tolerance at most): onto each violated plane in turn, which is
  // exact for orthogonal planes, then if needed along the neighbourhood's
  // mean normal. False when that direction does not work.
  bool push_outward(Vec3& x) const {
    auto worst_violation = [&]() {
      double violation = 0.0;
      for (const Plane& p : planes_) violation = std::max(violation, p.d - p.n.dot(x));
      return violation;
    };
    for (const Plane& p : planes_) {
      const double gap = p.d - p.n.dot(x);
      if (gap > 0.0) x += gap * p.n;
    }
    const double violation = worst_violation();
    if (violation == 0.0) return true;
    Vec3 mean = Vec3::Zero();
    for (const Plane& p : planes_) mean += p.n;
    mean.normalize();
    double min_cosine = 1.0;
    for (const Plane& p : planes_) min_cosine = std::min(min_cosine, p.n.dot(mean));
    if (min_cosine < kMinNudgeCosine) return false;
    // Twice the step that closes the worst gap, so rounding cannot leave a
    // residue; the step is ~1e-9 of the radius, its volume negligible.
    x += (2.0 * violation / min_cosine) * mean;
    return std::all_of(planes_.begin(), planes_.end(),
                       [&](const Plane& p) { return p.n.dot(x) >= p.d; });
  }

  // No kept face becomes degenerate or turns by more than the limit.
  bool faces_stay_valid(const Vec3& x) const {
    return std::all_of(kept_.begin(), kept_.end(), [&](const KeptFace& f) {
      const Vec3 area_vector = (f.b - x).cross(f.c - x);
      const double norm = area_vector.norm();
      const double longest =
          std::max({(f.b - x).squaredNorm(), (f.c - x).squaredNorm(), (f.c - f.b).squaredNorm()});
      if (!(norm > kDegenerateHeight * longest)) return false;
      return area_vector.dot(f.normal) >= min_cosine_ * norm;
    });
  }

  Mesh& mesh_;
  double min_cosine_;
  PlacementSolver solver_;
  std::vector<Plane> planes_;
  std::vector<KeptFace> kept_;
  Vec3 gradient_ = Vec3::Zero();  // d(added volume)/dx, mm^2
  double old_volume_ = 0.0;       // signed volume of the old neighbourhood about the midpoint
  double radius_ = 0.0;           // farthest neighbourhood vertex from the midpoint
};

struct HeapEntry {
  double cost;
  int edge;
  std::uint32_t version;
  bool operator>(const HeapEntry& other) const { return cost > other.cost; }
};

void validate_options(const ProgressiveHullOptions& options) {
  if (options.target_faces < 4) {
    throw InvalidInputError("progressive_hull: target_faces must be >= 4 (a tetrahedron), got " +
                            std::to_string(options.target_faces));
  }
  const double angle = options.max_normal_deviation_degrees;
  if (!std::isfinite(angle) || angle <= 0.0 || angle > 180.0) {
    throw InvalidInputError(
        "progressive_hull: max_normal_deviation_degrees must be in (0, 180], got " +
        std::to_string(angle) + "; 90 (the default) refuses flips and fold-overs");
  }
}

void validate_mesh(const IndexedMesh& mesh) {
  if (mesh.empty()) throw InvalidInputError("progressive_hull: the mesh has no faces");
  const MeshCheckReport check = check_mesh(mesh);
  if (check.boundary_edges > 0) {
    throw InvalidInputError("progressive_hull: the mesh is open (" +
                            std::to_string(check.boundary_edges) + " boundary edges in " +
                            std::to_string(check.boundary_loops) +
                            " holes); a hull must enclose a volume: fill the holes first");
  }
  if (!check.manifold()) {
    throw InvalidInputError(
        "progressive_hull: the mesh is not two-manifold (" +
        std::to_string(check.non_manifold_edges) + " edges with more than two faces, " +
        std::to_string(check.non_manifold_vertices) + " bow-tie vertices); repair it first");
  }
  if (!check.orientation_consistent()) {
    throw InvalidInputError("progressive_hull: the faces are inconsistently oriented (" +
                            std::to_string(check.inconsistently_oriented_edges) +
                            " edges traversed the same way by both faces); orient them "
                            "consistently outward first");
  }
  if (check.degenerate_faces > 0) {
    throw InvalidInputError("progressive_hull: the mesh has " +
                            std::to_string(check.degenerate_faces) +
                            " degenerate (zero-area) faces, which have no outward side; "
                            "remove them first");
  }
  const double volume = signed_volume(mesh);
  if (!(volume > 0.0)) {
    throw InvalidInputError("progressive_hull: the faces point inward (signed volume " +
                            std::to_string(volume) +
                            " mm^3); reverse every face's vertex order first");
  }
}

// Input vertices (used by a face) more than the tolerance outside the hull,
// and the largest signed distance of any of them.
void check_containment(const IndexedMesh& input, const IndexedMesh& hull,
                       ProgressiveHullReport& report) {
  const SignedDistance distance(hull);
  std::vector<bool> used(static_cast<size_t>(input.num_vertices()), false);
  for (Eigen::Index i = 0; i < input.F.size(); ++i)
    used[static_cast<size_t>(input.F.data()[i])] = true;
  report.vertices_outside = 0;
  report.max_outside_mm = 0.0;
  for (Eigen::Index v = 0; v < input.num_vertices(); ++v) {
    if (!used[static_cast<size_t>(v)]) continue;
    const double sd = distance.at(input.V.row(v).transpose());
    if (sd > kProgressiveHullOnSurfaceTolerance) ++report.vertices_outside;
    report.max_outside_mm = std::max(report.max_outside_mm, sd);
  }
}

}  // namespace

IndexedMesh progressive_hull(const IndexedMesh& mesh, const ProgressiveHullOptions& options,
                             ProgressiveHullReport* report) {
  validate_options(options);
  validate_indices_and_coordinates(mesh);
  validate_mesh(mesh);
  if (report != nullptr) {
    *report = ProgressiveHullReport{};
    report->faces_before = mesh.num_faces();
    report->faces_after = mesh.num_faces();
    report->volume_before = signed_volume(mesh);
    report->volume_after = report->volume_before;
  }
  if (options.target_faces >= mesh.num_faces()) return mesh;

  ConversionReport conversion;
  Mesh halfedge = to_halfedge(mesh, &conversion);
  if (!conversion.rejected_faces.empty()) {
    throw InvalidInputError(
        "progressive_hull: face " + std::to_string(conversion.rejected_faces.front()) + " (and " +
        std::to_string(conversion.rejected_faces.size() - 1) +
        " more) cannot be part of a manifold half-edge mesh; repair the mesh first");
  }
  halfedge.request_vertex_status();
  halfedge.request_edge_status();
  halfedge.request_face_status();

  CollapseEvaluator collapser(halfedge, options.max_normal_deviation_degrees);
  std::vector<std::uint32_t> versions(halfedge.n_edges(), 0);
  std::vector<std::uint32_t> seen(halfedge.n_edges(), 0);
  std::uint32_t round = 0;
  std::priority_queue<HeapEntry, std::vector<HeapEntry>, std::greater<>> heap;
  auto push = [&](Mesh::EdgeHandle e) {
    const auto index = static_cast<size_t>(e.idx());
    ++versions[index];
    if (const auto placement = collapser.evaluate(e)) {
      heap.push({placement->added_volume, e.idx(), versions[index]});
    }
  };
  for (const auto e : halfedge.edges()) push(e);

  auto faces = static_cast<Eigen::Index>(halfedge.n_faces());
  while (faces > options.target_faces && !heap.empty()) {
    const HeapEntry top = heap.top();
    heap.pop();
    const Mesh::EdgeHandle e(top.edge);
    if (halfedge.status(e).deleted() || top.version != versions[static_cast<size_t>(top.edge)]) {
      continue;
    }
    const auto placement = collapser.evaluate(e);
    if (!placement) continue;
    // Either direction gives the same mesh once the kept vertex moves; the
    // link condition (OpenMesh) keeps it two-manifold and of the same genus.
    Mesh::HalfedgeHandle h = halfedge.halfedge_handle(e, 0);
    if (!halfedge.is_collapse_ok(h)) {
      h = halfedge.opposite_halfedge_handle(h);
      if (!halfedge.is_collapse_ok(h)) continue;
    }
    const Mesh::VertexHandle kept = halfedge.to_vertex_handle(h);
    halfedge.collapse(h);
    halfedge.set_point(kept, to_mesh_point(placement->position));
    faces -= 2;
    // Every edge whose neighbourhood holds a face of the new fan.
    ++round;
    auto refresh_around = [&](Mesh::VertexHandle v) {
      for (const auto edge : halfedge.ve_range(v)) {
        auto& mark = seen[static_cast<size_t>(edge.idx())];
        if (mark == round) continue;
        mark = round;
        push(edge);
      }
    };
    refresh_around(kept);
    for (const auto neighbour : halfedge.vv_range(kept)) refresh_around(neighbour);
  }

  halfedge.delete_isolated_vertices();  // input vertices no face used
  halfedge.garbage_collection();
  IndexedMesh hull = to_indexed(halfedge);
  if (report != nullptr) {
    report->faces_after = hull.num_faces();
    report->volume_after = signed_volume(hull);
    check_containment(mesh, hull, *report);
  }
  return hull;
}

}  // namespace mmm::mesh

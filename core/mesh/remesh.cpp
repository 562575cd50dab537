// Isotropic remeshing after Botsch & Kobbelt 2004 ("A remeshing approach to
// multiresolution modeling", SGP), on OpenMesh's half-edge operations:
//
//   high = 4/3 L, low = 4/5 L
//   repeat `iterations` times:
//     split every edge longer than high at its midpoint (until none is left)
//     collapse every edge shorter than low into its midpoint when the link
//       condition holds, no new edge exceeds high and no face turns over
//     flip an edge when that brings its four vertices closer to valence 6
//       (4 on the boundary) and both new triangles keep their orientation
//     tangential relaxation: p <- c + n n^T (p - c), c the neighbours' centroid
//     project every vertex onto the closest point of the input (AABB tree)
//
// The bounds 4/5 and 4/3 are the ones of the paper: a split of an edge of
// length just above high leaves two edges above low, so split and collapse
// never undo each other.

#include "core/mesh/remesh.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::mesh {
namespace {

using Point = Mesh::Point;

// Beyond this many faces the output would not fit comfortably in memory; a
// target this small is almost certainly a unit mistake (m instead of mm).
constexpr double kMaxOutputFaces = 2e7;

// Twice the area vector of triangle (a, b, c).
Eigen::Vector3d area_vector(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  return (b - a).cross(c - a);
}

void validate(const IndexedMesh& mesh, const RemeshOptions& options) {
  const double length = options.target_edge_length;
  if (!std::isfinite(length) || length <= 0.0) {
    throw InvalidInputError(
        "remesh_uniform: target_edge_length must be a positive number of mm, "
        "got " +
        std::to_string(length));
  }
  if (options.iterations < 1) {
    throw InvalidInputError("remesh_uniform: iterations must be >= 1, got " +
                            std::to_string(options.iterations));
  }
  if (mesh.empty()) throw InvalidInputError("remesh_uniform: the mesh has no face");
  validate_indices_and_coordinates(mesh);
  double area = 0.0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    area += 0.5 * area_vector(mesh.V.row(mesh.F(f, 0)).transpose(),
                              mesh.V.row(mesh.F(f, 1)).transpose(),
                              mesh.V.row(mesh.F(f, 2)).transpose())
                      .norm();
  }
  // An equilateral triangle of side L has area sqrt(3)/4 L^2.
  const double estimated_faces = area / (std::sqrt(3.0) / 4.0 * length * length);
  if (estimated_faces > kMaxOutputFaces) {
    throw InvalidInputError("remesh_uniform: target_edge_length " + std::to_string(length) +
                            " mm would give about " + std::to_string(estimated_faces) +
                            " faces for a surface of " + std::to_string(area) +
                            " mm^2 (limit 2e7); check the unit (mm) of the edge length");
  }
}

class Remesher {
 public:
  Remesher(Mesh& mesh, const AabbTree& tree, double target)
      : mesh_(mesh), tree_(tree), high_(4.0 / 3.0 * target), low_(4.0 / 5.0 * target) {}

  void run(int iterations) {
    for (int round = 0; round < iterations; ++round) {
      split_long_edges();
      collapse_short_edges();
      equalize_valences();
      relax_tangentially();
      project_to_surface();
    }
  }

 private:
  [[nodiscard]] Eigen::Vector3d position(Mesh::VertexHandle v) const {
    return to_eigen(mesh_.point(v));
  }

  [[nodiscard]] double length(Mesh::EdgeHandle e) const {
    const auto h = mesh_.halfedge_handle(e, 0);
    return (position(mesh_.to_vertex_handle(h)) - position(mesh_.from_vertex_handle(h))).norm();
  }

  void split_long_edges() {
    bool split_any = true;
    while (split_any) {
      split_any = false;
      const size_t num_edges = mesh_.n_edges();
      for (size_t i = 0; i < num_edges; ++i) {
        const Mesh::EdgeHandle e(static_cast<int>(i));
        if (mesh_.status(e).deleted() || length(e) <= high_) continue;
        const auto h = mesh_.halfedge_handle(e, 0);
        const Eigen::Vector3d midpoint =
            0.5 * (position(mesh_.to_vertex_handle(h)) + position(mesh_.from_vertex_handle(h)));
        mesh_.split(e, to_mesh_point(midpoint));
        split_any = true;
      }
    }
  }

  // Would moving v0 and v1 to `target` (v0 merged into v1) turn over or
  // flatten any face that survives the collapse of h (v0 -> v1)?
  [[nodiscard]] bool collapse_keeps_orientation(Mesh::HalfedgeHandle h,
                                                const Eigen::Vector3d& target) const {
    const auto v0 = mesh_.from_vertex_handle(h);
    const auto v1 = mesh_.to_vertex_handle(h);
    const auto face_left = mesh_.face_handle(h);
    const auto face_right = mesh_.face_handle(mesh_.opposite_halfedge_handle(h));
    for (const auto moved : {v0, v1}) {
      for (const auto f : mesh_.vf_range(moved)) {
        if (f == face_left || f == face_right) continue;
        std::array<Eigen::Vector3d, 3> before;
        std::array<Eigen::Vector3d, 3> after;
        int k = 0;
        for (const auto v : mesh_.fv_range(f)) {
          before[k] = position(v);
          after[k] = (v == v0 || v == v1) ? target : before[k];
          ++k;
        }
        const Eigen::Vector3d n_before = area_vector(before[0], before[1], before[2]);
        const Eigen::Vector3d n_after = area_vector(after[0], after[1], after[2]);
        // Turned by more than 90 degrees, or squeezed to no area.
        if (n_before.dot(n_after) <= 0.0) return false;
      }
    }
    return true;
  }

  // Collapses h (from v0 into v1) when legal; returns whether it did.
  bool try_collapse(Mesh::HalfedgeHandle h) {
    const auto v0 = mesh_.from_vertex_handle(h);
    const auto v1 = mesh_.to_vertex_handle(h);
    if (mesh_.is_boundary(v0) || !mesh_.is_collapse_ok(h)) return false;
    // A boundary v1 must stay where it is; otherwise meet in the middle.
    const Eigen::Vector3d target =
        mesh_.is_boundary(v1) ? position(v1) : 0.5 * (position(v0) + position(v1));
    for (const auto moved : {v0, v1}) {
      for (const auto w : mesh_.vv_range(moved)) {
        if (w != v0 && w != v1 && (position(w) - target).norm() > high_) return false;
      }
    }
    if (!collapse_keeps_orientation(h, target)) return false;
    mesh_.set_point(v1, to_mesh_point(target));
    mesh_.collapse(h);
    return true;
  }

  void collapse_short_edges() {
    const size_t num_edges = mesh_.n_edges();
    for (size_t i = 0; i < num_edges; ++i) {
      const Mesh::EdgeHandle e(static_cast<int>(i));
      if (mesh_.status(e).deleted() || length(e) >= low_) continue;
      if (!try_collapse(mesh_.halfedge_handle(e, 0))) try_collapse(mesh_.halfedge_handle(e, 1));
    }
  }

  [[nodiscard]] int valence_deviation(Mesh::VertexHandle v, int change) const {
    const int target = mesh_.is_boundary(v) ? 4 : 6;
    return std::abs(static_cast<int>(mesh_.valence(v)) + change - target);
  }

  void equalize_valences() {
    const size_t num_edges = mesh_.n_edges();
    for (size_t i = 0; i < num_edges; ++i) {
      const Mesh::EdgeHandle e(static_cast<int>(i));
      if (mesh_.status(e).deleted() || mesh_.is_boundary(e) || !mesh_.is_flip_ok(e)) continue;
      // Faces (a, b, c) and (b, a, d); after the flip (a, d, c) and (d, b, c).
      const auto h = mesh_.halfedge_handle(e, 0);
      const auto a = mesh_.from_vertex_handle(h);
      const auto b = mesh_.to_vertex_handle(h);
      const auto c = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h));
      const auto d =
          mesh_.to_vertex_handle(mesh_.next_halfedge_handle(mesh_.opposite_halfedge_handle(h)));
      const int before = valence_deviation(a, 0) + valence_deviation(b, 0) +
                         valence_deviation(c, 0) + valence_deviation(d, 0);
      const int after = valence_deviation(a, -1) + valence_deviation(b, -1) +
                        valence_deviation(c, 1) + valence_deviation(d, 1);
      if (after >= before) continue;
      const Eigen::Vector3d normal = area_vector(position(a), position(b), position(c)) +
                                     area_vector(position(b), position(a), position(d));
      if (area_vector(position(a), position(d), position(c)).dot(normal) <= 0.0 ||
          area_vector(position(d), position(b), position(c)).dot(normal) <= 0.0) {
        continue;  // the quad is not convex seen along its normal
      }
      mesh_.flip(e);
    }
  }

  void relax_tangentially() {
    mesh_.update_face_normals();
    mesh_.update_vertex_normals();
    std::vector<Eigen::Vector3d> relaxed(mesh_.n_vertices());
    for (const auto v : mesh_.vertices()) {
      const Eigen::Vector3d p = position(v);
      relaxed[static_cast<size_t>(v.idx())] = p;
      if (mesh_.is_boundary(v)) continue;
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      int count = 0;
      for (const auto w : mesh_.vv_range(v)) {
        centroid += position(w);
        ++count;
      }
      if (count == 0) continue;
      centroid /= count;
      const Eigen::Vector3d n = to_eigen(mesh_.normal(v));
      relaxed[static_cast<size_t>(v.idx())] = centroid + n * n.dot(p - centroid);
    }
    for (const auto v : mesh_.vertices()) {
      mesh_.set_point(v, to_mesh_point(relaxed[static_cast<size_t>(v.idx())]));
    }
  }

  void project_to_surface() {
    for (const auto v : mesh_.vertices()) {
      if (mesh_.is_boundary(v)) continue;
      mesh_.set_point(v, to_mesh_point(tree_.closest_point(position(v)).point));
    }
  }

  Mesh& mesh_;
  const AabbTree& tree_;
  double high_;
  double low_;
};

}  // namespace

IndexedMesh remesh_uniform(const IndexedMesh& mesh, const RemeshOptions& options) {
  validate(mesh, options);
  ConversionReport conversion;
  Mesh halfedge = to_halfedge(mesh, &conversion);
  if (!conversion.rejected_faces.empty()) {
    throw InvalidInputError(
        "remesh_uniform: face " + std::to_string(conversion.rejected_faces.front()) + " (and " +
        std::to_string(conversion.rejected_faces.size() - 1) +
        " more) cannot be part of a manifold half-edge mesh (non-manifold edge, repeated vertex "
        "or inconsistent orientation); repair the mesh before remeshing it");
  }
  halfedge.request_vertex_status();
  halfedge.request_edge_status();
  halfedge.request_face_status();
  halfedge.delete_isolated_vertices();
  halfedge.request_face_normals();
  halfedge.request_vertex_normals();
  const AabbTree tree(mesh);
  Remesher(halfedge, tree, options.target_edge_length).run(options.iterations);
  halfedge.garbage_collection();
  return to_indexed(halfedge);
}

}  // namespace mmm::mesh
